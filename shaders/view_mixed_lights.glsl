// irview's mixed lights (runtime/mixed_lights.h): the direct irradiance of the lights an export leaves to the
// client, in glTF's units (KHR_lights_punctual): E = I cosθ / r² · window(r) for point and spot (window: glTF's
// range as the bake applies it, light_range.glsl; spot falloff as the baker's spot light kind,
// baker/lights/spot_light.cpp), E = I cosθ for directional; times the light's shadow-mask channel.
// Concatenated before view_mesh.frag; compiled in only where MIXED_LIGHTS is 1.
#if defined(MIXED_LIGHTS) && MIXED_LIGHTS
#define MAX_MIXED_LIGHTS 16
uniform int uMixedCount;
uniform vec4 uMixedPosition[MAX_MIXED_LIGHTS];   // xyz world position (point, spot); w: the kind's code (BAKE_LIGHT_*)
uniform vec4 uMixedDirection[MAX_MIXED_LIGHTS];  // xyz unit direction the light travels (spot, directional); w range (0: none)
uniform vec3 uMixedIntensity[MAX_MIXED_LIGHTS];  // colour × intensity: W/sr (point, spot) or W/m² (directional)
uniform vec2 uMixedCone[MAX_MIXED_LIGHTS];       // spot: cos(outer), 1 / max(0.001, cos(inner) − cos(outer))
uniform int uMixedChannel[MAX_MIXED_LIGHTS];     // shadow-mask channel 0..3, -1: unshadowed
uniform sampler2D uShadowMask;                   // RGBA visibility, linear, TEXCOORD_1 (white without a mask)

vec3 mixedIrradiance(vec3 p, vec3 n, vec2 uv1) {
  vec4 mask = texture(uShadowMask, uv1);
  vec3 e = vec3(0.0);
  for (int i = 0; i < uMixedCount; ++i) {
    vec4 pos = uMixedPosition[i], dir = uMixedDirection[i];
    vec3 l = -dir.xyz;
    float scale = 1.0;
    if (pos.w < 1.5) {
      vec3 d = pos.xyz - p;
      float r2 = max(dot(d, d), 1e-20);
      l = d * inversesqrt(r2);
      scale = rangeWindow(sqrt(r2), dir.w) / r2;
      if (pos.w > 0.5) {
        float t = clamp((dot(dir.xyz, -l) - uMixedCone[i].x) * uMixedCone[i].y, 0.0, 1.0);
        scale *= t * t;
      }
    }
    int c = uMixedChannel[i];
    float visibility = c < 0 ? 1.0 : mask[c];
    e += uMixedIntensity[i] * (max(dot(n, l), 0.0) * scale * visibility);
  }
  return e;
}
#endif
