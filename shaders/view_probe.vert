// irview's probe spheres: the box around one sphere (36 vertices from gl_VertexID, no vertex buffer); the
// fragment shader ray-casts the sphere inside it.
uniform mat4 uViewProjection;
uniform vec3 uCentre;
uniform float uRadius;
out vec3 vWorld;

void main() {
  const int faces[36] = int[36](0, 1, 3, 0, 3, 2, 4, 6, 7, 4, 7, 5, 0, 4, 5, 0, 5, 1,
                                2, 3, 7, 2, 7, 6, 0, 2, 6, 0, 6, 4, 1, 5, 7, 1, 7, 3);
  int c = faces[gl_VertexID];
  vec3 corner = vec3(float(c & 1), float((c >> 1) & 1), float((c >> 2) & 1)) * 2.0 - 1.0;
  vWorld = uCentre + uRadius * 1.01 * corner;
  gl_Position = uViewProjection * vec4(vWorld, 1.0);
}
