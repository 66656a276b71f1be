// irview shading: baseColor × lightmap + emissive, in linear radiance. The light map stores
// irradiance/π, so a Lambertian surface of albedo ρ shows ρ·map (docs/units.md).
// Compiled once per view (VIEW_MODE) and output (ENCODE_SRGB), both defined by the renderer: a
// software rasteriser pays for every instruction of a shader, taken branch or not, and for every
// varying, so each variant keeps only what it shows.
#ifndef VIEW_MODE
#define VIEW_MODE 0  // 0 lit, 1 lightmap only, 2 albedo only, 3 charts, 4 texel density, 5 wire lines
#endif
#ifndef ENCODE_SRGB
#define ENCODE_SRGB 0  // 1: exposure + sRGB here (window); 0: linear radiance out (offscreen)
#endif

in vec3 vNormal;
in vec2 vUv0;
in vec2 vUv1;
flat in float vChart;

uniform vec4 uBaseColorFactor;
uniform bool uHasBaseColorTex;
uniform sampler2D uBaseColorTex;   // linear (decoded from sRGB at load)
uniform bool uBaseColorUv1;        // the base colour texture reads TEXCOORD_1
uniform vec3 uEmissive;            // factor × KHR_materials_emissive_strength
uniform bool uHasEmissiveTex;
uniform sampler2D uEmissiveTex;
uniform bool uEmissiveUv1;
uniform bool uHasLightmap;
uniform sampler2D uLightmap;       // irradiance/π, linear
uniform float uLightmapScale;      // MOZ_lightmap intensity (1 for float pages)
uniform vec2 uLightmapSize;        // page size in texels (density checker)
uniform bool uAlphaMask;
uniform float uAlphaCutoff;
uniform float uExposureScale;      // 2^EV (ENCODE_SRGB only)
uniform vec3 uLineColor;

out vec4 fragColor;

vec3 chartColor(float id) {
  // Golden-ratio hue walk: neighbouring ids get distinct hues.
  float h = fract(id * 0.61803398875 + 0.1);
  vec3 k = clamp(abs(fract(h + vec3(0.0, 2.0 / 3.0, 1.0 / 3.0)) * 6.0 - 3.0) - 1.0, 0.0, 1.0);
  return mix(vec3(0.25), k, 0.8);
}

vec3 encodeSrgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

vec4 baseColor() {
  vec4 base = uBaseColorFactor;
  if (uHasBaseColorTex) base *= texture(uBaseColorTex, uBaseColorUv1 ? vUv1 : vUv0);
  if (uAlphaMask && base.a < uAlphaCutoff) discard;
  return base;
}

vec3 lightmap() { return uHasLightmap ? texture(uLightmap, vUv1).rgb * uLightmapScale : vec3(1.0); }

void main() {
  vec3 color;
#if VIEW_MODE == 0
  vec3 emissive = uEmissive;
  if (uHasEmissiveTex) emissive *= texture(uEmissiveTex, uEmissiveUv1 ? vUv1 : vUv0).rgb;
  color = baseColor().rgb * lightmap() + emissive;
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
#if ENCODE_SRGB && VIEW_MODE != 5
  color = encodeSrgb(color * uExposureScale);
#endif
  fragColor = vec4(color, 1.0);
}
