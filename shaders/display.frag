#version 330 core
// keithray display: tone maps the mean radiance texture exactly as kr::tonemap
// (src/core/image.cpp) does: per channel, sigmoid v/(1+v) after `exposure`; linear
// v * inv_max, with exposure / max over all channels of the whole image computed on the CPU;
// or sRGB: the transfer curve of v * exposure clamped to [0, 1]. Then clamp, x255, round.
in vec2 uv;
uniform sampler2D radiance;
uniform int op;           // 0: sigmoid, 1: linear, 2: srgb (kr::ToneMap order); 3: 8-bit as is
uniform float exposure;   // sigmoid and srgb: 2^EV
uniform float inv_max;    // linear only: 2^EV / max channel value, 0 for a black image
out vec4 colour;

void main() {
    vec3 v = texture(radiance, uv).rgb;
    vec3 e = v * exposure;
    // inf / (1 + inf) is NaN in GLSL: radiance beyond float range saturates, as in the core.
    vec3 sigmoid = mix(e / (1.0 + e), vec3(1.0), isinf(e));
    // kr::srgb_encode; NaN and negative values stay as they are (quantised to 0 below).
    vec3 c = min(e, vec3(1.0));
    vec3 srgb = mix(1.055 * pow(max(c, vec3(0.0)), vec3(1.0 / 2.4)) - 0.055, 12.92 * c, lessThanEqual(c, vec3(0.0031308)));
    vec3 mapped = op == 0 ? sigmoid : op == 1 ? v * inv_max : op == 2 ? srgb : v;
    // kr::quantize_unit: !(v > 0) -> 0 (NaN included), v >= 1 -> 255, else round(v * 255).
    vec3 unit = clamp(mapped, 0.0, 1.0);
    unit = mix(vec3(0.0), unit, greaterThan(mapped, vec3(0.0)));
    // Already a multiple of 1/255, so the 8-bit framebuffer stores exactly that level.
    colour = vec4(floor(unit * 255.0 + 0.5) / 255.0, 1.0);
}
