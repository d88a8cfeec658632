#version 330 core
// keithray display: tone maps the mean radiance texture exactly as kr::tonemap
// (src/core/image.cpp) does: per channel, sigmoid v/(1+v) after `exposure`, or linear
// v * inv_max with one max over all channels of the whole image (computed on the CPU;
// exposure cancels there, as in the core); then clamp, x255, round, no gamma.
in vec2 uv;
uniform sampler2D radiance;
uniform int op;           // 0: sigmoid, 1: linear (kr::ToneMap order)
uniform float exposure;   // sigmoid only
uniform float inv_max;    // linear only: 1 / max channel value, 0 for a black image
out vec4 colour;

void main() {
    vec3 v = texture(radiance, uv).rgb;
    vec3 e = v * exposure;
    // inf / (1 + inf) is NaN in GLSL: radiance beyond float range saturates, as in the core.
    vec3 sigmoid = mix(e / (1.0 + e), vec3(1.0), isinf(e));
    vec3 mapped = op == 0 ? sigmoid : v * inv_max;
    // kr::quantize_unit: !(v > 0) -> 0 (NaN included), v >= 1 -> 255, else round(v * 255).
    vec3 unit = clamp(mapped, 0.0, 1.0);
    unit = mix(vec3(0.0), unit, greaterThan(mapped, vec3(0.0)));
    // Already a multiple of 1/255, so the 8-bit framebuffer stores exactly that level.
    colour = vec4(floor(unit * 255.0 + 0.5) / 255.0, 1.0);
}
