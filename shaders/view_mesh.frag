// irview shading: baseColor × lightmap + emissive, in linear radiance. The light map stores
// irradiance/π, so a Lambertian surface of albedo ρ shows ρ·map (docs/units.md). With directional maps
// (DIRECTIONAL) the map is reconstructed for the normal map's normal from L0 and the L1 pages.
// Compiled once per view, output encoding and material features, all defined by the renderer:
// llvmpipe executes both sides of a branch, even on a uniform, so a texture fetch behind
// `if (uHasTexture)` is paid by every fragment; each variant keeps only what it shows.
#ifndef VIEW_MODE
#define VIEW_MODE 0  // 0 lit, 1 lightmap only, 2 albedo only, 3 charts, 4 texel density, 5 wire lines
#endif
#ifndef OUTPUT
#define OUTPUT 0  // 0: linear radiance (offscreen); 1: exposure + sRGB encode (display)
#endif
#ifndef BASE_TEX
#define BASE_TEX 0  // base colour texture: 0 none, 1 reads TEXCOORD_0, 2 reads TEXCOORD_1
#endif
#ifndef EMISSIVE_TEX
#define EMISSIVE_TEX 0  // emissive texture: 0 none, 1 TEXCOORD_0, 2 TEXCOORD_1
#endif
#ifndef HAS_LIGHTMAP
#define HAS_LIGHTMAP 0  // 0: no map (shows albedo, map = 1)
#endif
#ifndef ALPHA_MASK
#define ALPHA_MASK 0  // 1: discard below uAlphaCutoff (glTF alphaMode MASK)
#endif
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
#ifndef DIRECTIONAL
#define DIRECTIONAL 0  // L1 SH with the normal map: 0 off, 1 normal map on TEXCOORD_0, 2 on TEXCOORD_1
#endif
#ifndef NEED_TANGENT
#define NEED_TANGENT 0
#endif
#ifndef MIXED_LIGHTS
#define MIXED_LIGHTS 0  // 1: add the export's runtime lights (view_mixed_lights.glsl), needs vPosition
#endif
#ifndef PROBE_LIT
#define PROBE_LIT 0  // 1: lit by the probes instead of a map (a probe-lit object, docs/export.md), needs vPosition
#endif
#ifndef EMITTER_TRIANGLES
#define EMITTER_TRIANGLES 0  // the probes' exact emitters (probe_emitters.glsl, concatenated before this file)
#endif

#if NEED_NORMAL
in vec3 vNormal;
#endif
#if NEED_UV0
in vec2 vUv0;
#endif
#if NEED_UV1
in vec2 vUv1;
#endif
#if NEED_CHART
flat in float vChart;
#endif
#if NEED_TANGENT
in vec4 vTangent;
#endif
#if MIXED_LIGHTS || PROBE_LIT
in vec3 vPosition;
#endif

uniform vec4 uBaseColorFactor;
uniform sampler2D uBaseColorTex;   // linear (decoded from sRGB by the sampler or at load)
uniform vec3 uEmissive;            // factor × KHR_materials_emissive_strength
uniform sampler2D uEmissiveTex;
uniform mat3 uBaseColorUvTransform;  // KHR_texture_transform on (u, v, 1); the identity without it
uniform mat3 uEmissiveUvTransform;
uniform sampler2D uLightmap;       // irradiance/π, linear
uniform float uLightmapScale;      // MOZ_lightmap intensity (1 for float pages)
uniform vec2 uLightmapSize;        // page size in texels (density checker)
uniform float uAlphaCutoff;
uniform float uExposureScale;      // 2^EV (OUTPUT 1)
uniform vec3 uLineColor;
uniform sampler2D uNormalTex;      // glTF normalTexture, linear: tangent-space normal × 0.5 + 0.5
uniform float uNormalScale;        // normalTexture.scale
uniform sampler2D uL1x, uL1y, uL1z;  // L1 pages (values: world x, y, z component of t per colour channel)
#if PROBE_LIT
// The probes over the object as irview's probe spheres take them (probe_view.h): SH at the centre, its gradient,
// and the sun level (zero irradiance and SH without one).
uniform vec3 uCentre;
uniform vec3 uSh[9];
uniform vec3 uShGradient[27];  // ∂uSh/∂x (0..8), ∂uSh/∂y (9..17), ∂uSh/∂z (18..26)
uniform vec3 uSunDirection;
uniform vec3 uSunIrradiance;
uniform vec3 uSunSh[9];
uniform float uSunVisibility;
uniform vec3 uSunGradient;
#endif

out vec4 fragColor;

#if BASE_TEX == 1
#define BASE_UV vUv0
#elif BASE_TEX == 2
#define BASE_UV vUv1
#endif
#if DIRECTIONAL == 1
#define NORMAL_UV vUv0
#elif DIRECTIONAL == 2
#define NORMAL_UV vUv1
#endif
#if EMISSIVE_TEX == 1
#define EMISSIVE_UV vUv0
#elif EMISSIVE_TEX == 2
#define EMISSIVE_UV vUv1
#endif

vec3 chartColor(float id) {
  // Golden-ratio hue walk: neighbouring ids get distinct hues.
  float h = fract(id * 0.61803398875 + 0.1);
  vec3 k = clamp(abs(fract(h + vec3(0.0, 2.0 / 3.0, 1.0 / 3.0)) * 6.0 - 3.0) - 1.0, 0.0, 1.0);
  return mix(vec3(0.25), k, 0.8);
}

// encodeSrgb(): view_encode.glsl (shared with the sky, view_sky.frag).

vec4 baseColor() {
  vec4 base = uBaseColorFactor;
#if BASE_TEX
  base *= texture(uBaseColorTex, (uBaseColorUvTransform * vec3(BASE_UV, 1.0)).xy);
#endif
#if ALPHA_MASK
  if (base.a < uAlphaCutoff) discard;
#endif
  return base;
}

#if DIRECTIONAL
// The world normal after the normal map (glTF 2.0: n = normalize(T·x + B·y + N·z), xy × scale, B =
// cross(N, T)·w), with N the interpolated vertex normal and T made orthogonal to it.
vec3 mappedNormal(vec3 ng) {
  vec3 t = vTangent.xyz - ng * dot(ng, vTangent.xyz);
  t *= inversesqrt(max(dot(t, t), 1e-20));
  vec3 b = cross(ng, t) * (vTangent.w < 0.0 ? -1.0 : 1.0);
  vec3 m = texture(uNormalTex, NORMAL_UV).xyz * 2.0 - 1.0;
  m.xy *= uNormalScale;
  return normalize(t * m.x + b * m.y + ng * m.z);
}
#endif

vec3 lightmap() {
#if HAS_LIGHTMAP && DIRECTIONAL
  // transport/directional.h: value(n) = max(0, L0 (n_g·n) + t·n); the max is the deringing (one linear term
  // is exact wherever no light arrives from below n's horizon, and would go negative where it does).
  vec3 ng = normalize(vNormal);
  vec3 n = mappedNormal(ng);
  vec3 l0 = texture(uLightmap, vUv1).rgb * uLightmapScale;
  vec3 v = l0 * dot(ng, n) + texture(uL1x, vUv1).rgb * n.x + texture(uL1y, vUv1).rgb * n.y +
           texture(uL1z, vUv1).rgb * n.z;
  return max(v, vec3(0.0));
#elif HAS_LIGHTMAP
  return texture(uLightmap, vUv1).rgb * uLightmapScale;
#elif PROBE_LIT
  // As view_probe.frag at this point and normal: max(0, SH(p) without the sun) + the sun's exact clamped cosine.
  vec3 o = vPosition - uCentre, n = normalize(vNormal), sh[9];
  float v = clamp(uSunVisibility + dot(o, uSunGradient), 0.0, 1.0);
  for (int k = 0; k < 9; ++k)
    sh[k] = uSh[k] + o.x * uShGradient[k] + o.y * uShGradient[9 + k] + o.z * uShGradient[18 + k] - v * uSunSh[k];
  vec3 e = max(shIrradiance(sh, n), vec3(0.0)) + v * uSunIrradiance * max(0.0, -dot(n, uSunDirection));
#if EMITTER_TRIANGLES > 0
  e += exactEmitterLight(vPosition, n, o);
#endif
  return e;
#else
  return vec3(1.0);
#endif
}

void main() {
  vec3 color;
#if VIEW_MODE == 0
  vec3 emissive = uEmissive;
#if EMISSIVE_TEX
  emissive *= texture(uEmissiveTex, (uEmissiveUvTransform * vec3(EMISSIVE_UV, 1.0)).xy).rgb;
#endif
  vec3 base = baseColor().rgb;
  color = base * lightmap() + emissive;
#if MIXED_LIGHTS
  color += base * (1.0 / 3.14159265358979) * mixedIrradiance(vPosition, normalize(vNormal), vUv1);
#endif
#elif VIEW_MODE == 1
  baseColor();  // alpha-mask holes stay holes
  color = lightmap();
#elif VIEW_MODE == 2
  color = baseColor().rgb;
#elif VIEW_MODE == 3
  baseColor();
  color = chartColor(vChart) * (0.35 + 0.65 * abs(normalize(vNormal).y * 0.5 + 0.5));
#elif VIEW_MODE == 4
  baseColor();
  vec2 cell = floor(vUv1 * uLightmapSize);
  color = chartColor(vChart) * mix(0.35, 1.0, mod(cell.x + cell.y, 2.0));
#else
  color = uLineColor;
#endif
#if OUTPUT == 1 && VIEW_MODE != 5
  color = encodeSrgb(color * uExposureScale);
#endif
  fragColor = vec4(color, 1.0);
}
