// Depth-only shadow pass: world positions through one shadow view's clip matrix (a cube face in the
// VPL's normal-aligned frame, a spot frustum or a directional ortho box). No geometry shader.
// VPL cubes are tiles of one depth atlas: a face is kept inside its tile by clip distances against its
// rectangle in normalised device coordinates (the whole face, or the upper half of a side face plus a
// texel), not by a scissor, because on llvmpipe a scissor change per face cost about as much as drawing
// a small scene's face. The viewport still maps the face onto its tile.
layout(location = 0) in vec3 position;
uniform vec4 shadowView[5];  // [0..3]: clip matrix columns; [4]: the face rectangle (x0, x1, y0, y1) in NDC
void main() {
  vec4 c = mat4(shadowView[0], shadowView[1], shadowView[2], shadowView[3]) * vec4(position, 1.0);
  vec4 r = shadowView[4];
  gl_ClipDistance[0] = c.x - r.x * c.w;
  gl_ClipDistance[1] = r.y * c.w - c.x;
  gl_ClipDistance[2] = c.y - r.z * c.w;
  gl_ClipDistance[3] = r.w * c.w - c.y;
  gl_Position = c;
}
