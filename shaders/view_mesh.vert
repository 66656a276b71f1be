// irview: world-space triangles (positions are already transformed by the loader).
// The renderer defines which attributes the variant reads (NEED_UV0, NEED_UV1, NEED_NORMAL,
// NEED_CHART): llvmpipe sets up a plane equation per varying per triangle on its serial main thread
// and interpolates every varying per fragment, so a varying nobody reads is pure cost.
#ifndef NEED_UV0
#define NEED_UV0 1
#endif
#ifndef NEED_UV1
#define NEED_UV1 1
#endif
#ifndef NEED_NORMAL
#define NEED_NORMAL 1
#endif
#ifndef NEED_CHART
#define NEED_CHART 1
#endif

layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec2 aUv0;
layout(location = 3) in vec2 aUv1;
layout(location = 4) in float aChart;

uniform mat4 uViewProjection;

#if NEED_NORMAL
out vec3 vNormal;
#endif
#if NEED_UV0
out vec2 vUv0;
#endif
#if NEED_UV1
out vec2 vUv1;
#endif
#if NEED_CHART
flat out float vChart;
#endif

void main() {
#if NEED_NORMAL
  vNormal = aNormal;
#endif
#if NEED_UV0
  vUv0 = aUv0;
#endif
#if NEED_UV1
  vUv1 = aUv1;
#endif
#if NEED_CHART
  vChart = aChart;
#endif
  gl_Position = uViewProjection * vec4(aPosition, 1.0);
}
