// Depth-only shadow pass: world positions through one shadow view's clip matrix (a cube face in the
// VPL's normal-aligned frame, a spot frustum or a directional ortho box). No geometry shader.
layout(location = 0) in vec3 position;
uniform mat4 shadowClip;
void main() { gl_Position = shadowClip * vec4(position, 1.0); }
