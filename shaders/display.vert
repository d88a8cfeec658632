#version 330 core
// keithray display: one textured quad, drawn as a 4-vertex triangle strip with no
// vertex buffer. `rect` is the quad in normalised device coordinates (x0, y0, x1, y1),
// y0 at the top. uv (0,0) is the image's top-left pixel: rows are uploaded top row first.
uniform vec4 rect;
out vec2 uv;

void main() {
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1));  // (0,0) (1,0) (0,1) (1,1)
    uv = corner;
    gl_Position = vec4(mix(rect.x, rect.z, corner.x), mix(rect.y, rect.w, corner.y), 0.0, 1.0);
}
