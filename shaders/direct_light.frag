// Direct light from one punctual light (KHR_lights_punctual) with its shadow map, exact apart from
// the shadow-map resolution: value = I(ω) cosθx / r² / π (point, spot) or E cosθx / π (directional).
layout(binding = 0) uniform sampler2DArray gPositionWeight;
layout(binding = 1) uniform sampler2DArray gNormal;
layout(binding = 2) uniform sampler2DArray cubeMaps;     // point (and wide spot): 6 face layers
layout(binding = 3) uniform sampler2D mapDepth;          // spot (perspective) / directional (ortho)
layout(binding = 4) uniform sampler2DArray gGeomNormal;  // the sample's triangle's normal (bias, self-shadow)

uniform int layers;
uniform int lightType;         // 0 point, 1 spot, 2 directional
uniform int shadowKind;        // 0 cube, 1 perspective 2D, 2 orthographic 2D
uniform vec3 lightPosition;
uniform vec3 lightDirection;   // direction light travels (spot, directional)
uniform vec3 lightIntensity;   // colour × intensity (W/sr or W/m²)
uniform float lightRange;      // 0: infinite
uniform float cosOuter, spotScale;  // spot falloff: t = clamp((cos − cosOuter)·spotScale, 0, 1), I·t²
uniform mat4 shadowClip;       // 2D maps: world → clip
uniform float nearPlane;       // perspective maps: near plane (reversed-Z depth = near / distance)
uniform float orthoDepthRange; // ortho: metres per unit of depth
uniform float constantBias, slopeBias, normalOffset;
uniform float texelAngle;      // cube / perspective: angle of one texel (rad); ortho: texel size (m)

layout(location = 0) out vec4 result;

// 1 when the point p (normal n, cosθ to the light) is lit according to the shadow map.
float lit(vec3 p, vec3 n, float cosTheta, float r) {
  float footprint = shadowKind == 2 ? texelAngle : r * texelAngle;
  vec3 q = p + n * (normalOffset * footprint);
  float bias = shadowBias(constantBias, slopeBias, footprint, cosTheta);
  if (shadowKind == 0) {
    vec3 local = q - lightPosition;
    float axisDistance;
    float depth = cubeDepth(cubeMaps, 0, local, axisDistance);
    return cubeLit(depth, axisDistance, nearPlane, bias) ? 1.0 : 0.0;
  }
  vec4 c = shadowClip * vec4(q, 1.0);
  if (c.w <= 0.0) return 0.0;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return shadowKind == 2 ? 1.0 : 0.0;
  float depth = textureLod(mapDepth, uv, 0.0).r;
  if (shadowKind == 1) {
    return cubeLit(depth, c.w, nearPlane, bias) ? 1.0 : 0.0;
  }
  return c.z * orthoDepthRange > depth * orthoDepthRange + bias ? 0.0 : 1.0;
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec3 sum = vec3(0.0);
  for (int l = 0; l < layers; ++l) {
    vec4 pw = texelFetch(gPositionWeight, ivec3(px, l), 0);
    if (pw.w <= 0.0) continue;
    vec3 n = texelFetch(gNormal, ivec3(px, l), 0).xyz;
    vec3 toLight;
    float r = 1.0;
    vec3 e;
    if (lightType == 2) {
      toLight = -lightDirection;
      e = lightIntensity;
    } else {
      vec3 d = lightPosition - pw.xyz;
      r = length(d);
      if (r <= 0.0 || (lightRange > 0.0 && r > lightRange)) continue;
      toLight = d / r;
      vec3 I = lightIntensity;
      if (lightType == 1) {
        float t = clamp((dot(lightDirection, -toLight) - cosOuter) * spotScale, 0.0, 1.0);
        I *= t * t;
      }
      e = I / (r * r);
    }
    float cosTheta = dot(n, toLight);
    vec3 ng = texelFetch(gGeomNormal, ivec3(px, l), 0).xyz;
    float cosGeom = dot(ng, toLight);  // ≤ 0: the sample's own triangle hides the light
    if (cosTheta <= 0.0 || cosGeom <= 0.0 || max(e.r, max(e.g, e.b)) <= 0.0) continue;
    sum += pw.w * e * cosTheta * lit(pw.xyz, n, cosGeom, r);
  }
  result = vec4(sum / kPi, 0.0);
}
