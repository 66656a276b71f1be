// irview: world-space triangles (positions are already transformed by the loader).
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv0;
layout(location = 3) in vec2 aUv1;
layout(location = 4) in float aChart;

uniform mat4 uViewProjection;

out vec3 vNormal;
out vec2 vUv0;
out vec2 vUv1;
flat out float vChart;

void main() {
  vNormal = aNormal;
  vUv0 = aUv0;
  vUv1 = aUv1;
  vChart = aChart;
  gl_Position = uViewProjection * vec4(aPosition, 1.0);
}
