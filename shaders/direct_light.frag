// Direct light from one punctual light (KHR_lights_punctual) with its shadow map, exact apart from
// the shadow-map resolution: value = I(ω) cosθx / r² · window(r) / π (point, spot, IES; window: glTF's range,
// light_range.glsl) or E cosθx / π (directional).
layout(binding = BAKE_UNIT_POSITION_WEIGHT) uniform sampler2DArray gPositionWeight;
layout(binding = BAKE_UNIT_NORMAL) uniform sampler2DArray gNormal;
layout(binding = BAKE_UNIT_LIGHT_CUBE) uniform sampler2DArray cubeMaps;     // point (and wide spot): 6 face layers
layout(binding = BAKE_UNIT_LIGHT_MAP) uniform sampler2D mapDepth;          // spot (perspective) / directional (ortho)
layout(binding = BAKE_UNIT_GEOMETRIC_NORMAL) uniform sampler2DArray gGeomNormal;  // the sample's triangle's normal (bias, self-shadow)
layout(binding = BAKE_UNIT_GLASS_CUBE) uniform sampler2DArray glassCube;    // see-through primitives alone: cube faces
layout(binding = BAKE_UNIT_GLASS_MAP) uniform sampler2D glassMap;          // see-through primitives alone: spot / directional map
layout(binding = BAKE_UNIT_IES_PROFILE) uniform sampler2D iesProfile;    // IES: candela, x: φ over [0, 360°], y: θ over [0, 180°]
uniform int seeThroughMaps;    // 1: the glass maps hold the scene's MASK / BLEND / transmissive primitives

uniform int layers;
uniform int lightType;         // BAKE_LIGHT_POINT, _SPOT, _DIRECTIONAL or _IES (bake_interface.glsl)
uniform int shadowKind;        // BAKE_SHADOW_CUBE, _PERSPECTIVE (2D) or _ORTHOGRAPHIC (2D)
uniform vec3 lightPosition;
uniform vec3 lightDirection;   // direction light travels (spot, directional); IES: the profile's nadir
uniform vec3 lightAxisX;       // IES: the profile's horizontal angle 0 (unit, orthogonal to lightDirection)
uniform vec3 lightIntensity;   // colour × intensity (W/sr or W/m²)
uniform float lightRange;      // 0: infinite (rangeWindow)
uniform float lightCutoff;     // the bake's cut of a light without range (Light::cutoff); 0: none
uniform float cosOuter, spotScale;  // spot falloff: t = clamp((cos − cosOuter)·spotScale, 0, 1), I·t²
uniform mat4 shadowClip;       // 2D maps: world → clip
uniform mat4 shadowClipInverse;  // 2D maps: clip → world (contact check)
uniform int contactFlags;      // 1: alpha gets the light of lookups the map cannot resolve (contacts, edges)
uniform float nearPlane;       // perspective maps: near plane (reversed-Z depth = near / distance)
uniform float orthoDepthRange; // ortho: metres per unit of depth
uniform float constantBias, slopeBias, normalOffset;
uniform float texelAngle;      // cube / perspective: angle of one texel (rad); ortho: texel size (m)

layout(location = 0) out vec4 result;
#ifdef DIRECTIONAL
// Directional maps: the light's tangential irradiance vector t, world axis k in target 1 + k (as
// vpl_accumulate.frag).
layout(location = 1) out vec4 l1x;
layout(location = 2) out vec4 l1y;
layout(location = 3) out vec4 l1z;
#endif

// Contact check of a lit lookup (see ambiguousWeight in vpl_accumulate.frag): the stored surface, put
// back at the centre of its texel, must not lie in front of the receiver's plane (normal ng through p).
// In front of it, it is something else that the bias let through: a contact the map cannot resolve.
// Tolerance: 1e-5 of the scale for float rounding plus 5% of a texel's footprint (the rasteriser snaps
// vertices to a sub-texel grid, which tilts a stored plane by a fraction of its change across a texel).
bool inFrontOfPlane(vec3 stored, vec3 p, vec3 ng, float scale, float footprint) {
  return dot(ng, stored - p) > 1e-5 * scale + 0.01 * footprint;
}

// Shadow edges: where the 2×2 texels around the lookup disagree, the one texel read decides a result the
// map cannot resolve (the edge lies somewhere inside that texel): ambiguous as well (contactFlags).
bool mixed(bvec4 litTexels) { return any(litTexels) && !all(litTexels); }

// 1 when the point p (normal n, cosθ to the light) is lit according to the shadow map; `ambiguous` set
// when that answer may be wrong: a contact the bias let through, or a shadow edge (contactFlags).
float lit(vec3 p, vec3 n, vec3 ng, float cosTheta, float r, out bool ambiguous) {
  ambiguous = false;
  float footprint = shadowKind == BAKE_SHADOW_ORTHOGRAPHIC ? texelAngle : r * texelAngle;
  vec3 q = p + n * (normalOffset * footprint);
  float bias = shadowBias(constantBias, slopeBias, footprint, cosTheta);
  if (shadowKind == BAKE_SHADOW_CUBE) {
    vec3 local = q - lightPosition;
    float axisDistance;
    float depth = cubeDepth(cubeMaps, 0, local, axisDistance);
    bool isLit = cubeLit(depth, axisDistance, nearPlane, bias);
    if (contactFlags != 0) {
      if (isLit && depth > 0.0) {
        // The stored surface at the centre of its texel (axis distance near / depth).
        vec3 stored = lightPosition + cubeTexelCentreDirection(local, textureSize(cubeMaps, 0).x) * (nearPlane / depth);
        ambiguous = inFrontOfPlane(stored, p, ng, length(stored - lightPosition), footprint);
      }
      // The 2×2 texels around the lookup in its face (as cubeDepth's table).
      int face;
      vec2 sctc;
      float axisUnused;
      cubeFaceCoords(local, face, sctc, axisUnused);
      int size = textureSize(cubeMaps, 0).x;
      ivec2 t0 = clamp(ivec2(floor((sctc / axisDistance * 0.5 + 0.5) * float(size) - 0.5)), ivec2(0), ivec2(size - 2));
      vec4 d = vec4(texelFetch(cubeMaps, ivec3(t0, face), 0).r, texelFetch(cubeMaps, ivec3(t0 + ivec2(1, 0), face), 0).r,
                    texelFetch(cubeMaps, ivec3(t0 + ivec2(0, 1), face), 0).r, texelFetch(cubeMaps, ivec3(t0 + 1, face), 0).r);
      ambiguous = ambiguous || mixed(lessThanEqual(axisDistance * d, vec4(nearPlane) + bias * d));
      if (isLit && seeThroughMaps != 0) {  // a see-through surface in front: for the rays
        float unused;
        float glass = cubeDepth(glassCube, 0, local, unused);
        ambiguous = ambiguous || (glass > 0.0 && !cubeLit(glass, axisDistance, nearPlane, bias));
      }
    }
    return isLit ? 1.0 : 0.0;
  }
  vec4 c = shadowClip * vec4(q, 1.0);
  if (c.w <= 0.0) return 0.0;
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return shadowKind == BAKE_SHADOW_ORTHOGRAPHIC ? 1.0 : 0.0;
  // The texel picked here (not by the sampler's own rounding), so its centre below is the one read.
  ivec2 size = textureSize(mapDepth, 0);
  ivec2 texel = clamp(ivec2(uv * vec2(size)), ivec2(0), size - 1);
  float depth = texelFetch(mapDepth, texel, 0).r;
  bool isLit = shadowKind == BAKE_SHADOW_PERSPECTIVE ? cubeLit(depth, c.w, nearPlane, bias)
                               : !(c.z * orthoDepthRange > depth * orthoDepthRange + bias);
  bool drawn = shadowKind == BAKE_SHADOW_PERSPECTIVE ? depth > 0.0 : depth < 1.0;
  if (contactFlags != 0) {
    if (isLit && drawn) {
      // The stored surface at the centre of its texel, back in world space.
      vec2 centre = (vec2(texel) + 0.5) / vec2(size);
      vec4 w = shadowClipInverse * vec4(centre * 2.0 - 1.0, depth, 1.0);
      vec3 stored = w.xyz / w.w;
      ambiguous = inFrontOfPlane(stored, p, ng, shadowKind == BAKE_SHADOW_ORTHOGRAPHIC ? orthoDepthRange : length(stored - lightPosition),
                                 footprint);
    }
    ivec2 t0 = clamp(ivec2(floor(uv * vec2(size) - 0.5)), ivec2(0), size - 2);
    vec4 d = vec4(texelFetch(mapDepth, t0, 0).r, texelFetch(mapDepth, t0 + ivec2(1, 0), 0).r,
                  texelFetch(mapDepth, t0 + ivec2(0, 1), 0).r, texelFetch(mapDepth, t0 + 1, 0).r);
    bvec4 l = shadowKind == BAKE_SHADOW_PERSPECTIVE ? lessThanEqual(c.w * d, vec4(nearPlane) + bias * d)
                              : lessThanEqual(vec4(c.z * orthoDepthRange), d * orthoDepthRange + bias);
    ambiguous = ambiguous || mixed(l);
    if (isLit && seeThroughMaps != 0) {  // a see-through surface in front: for the rays
      float glass = texelFetch(glassMap, texel, 0).r;
      ambiguous = ambiguous || (shadowKind == BAKE_SHADOW_PERSPECTIVE ? glass > 0.0 && !cubeLit(glass, c.w, nearPlane, bias)
                                                : glass < 1.0 && c.z * orthoDepthRange > glass * orthoDepthRange + bias);
    }
  }
  return isLit ? 1.0 : 0.0;
}

// An IES profile's candela towards a unit direction leaving the light, bilinear in (φ, θ) on the table's grid
// (IesProfile::table).
float iesCandela(vec3 dir) {
  float theta = atan(length(cross(dir, lightDirection)), dot(dir, lightDirection));  // exact near the nadir
  vec3 y = cross(-lightDirection, lightAxisX);
  float px = dot(dir, lightAxisX), py = dot(dir, y);
  float phi = (abs(px) + abs(py) > 0.0) ? atan(py, px) : 0.0;
  if (phi < 0.0) phi += 2.0 * kPi;
  ivec2 size = textureSize(iesProfile, 0);
  vec2 f = vec2(phi / (2.0 * kPi) * float(size.x - 1), theta / kPi * float(size.y - 1));
  ivec2 i0 = clamp(ivec2(floor(f)), ivec2(0), size - 2);
  vec2 t = clamp(f - vec2(i0), 0.0, 1.0);
  float c00 = texelFetch(iesProfile, i0, 0).r, c10 = texelFetch(iesProfile, i0 + ivec2(1, 0), 0).r;
  float c01 = texelFetch(iesProfile, i0 + ivec2(0, 1), 0).r, c11 = texelFetch(iesProfile, i0 + ivec2(1, 1), 0).r;
  return mix(mix(c00, c10, t.x), mix(c01, c11, t.x), t.y);
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec3 sum = vec3(0.0);
  float leak = 0.0;
#ifdef DIRECTIONAL
  vec3 tx = vec3(0.0), ty = vec3(0.0), tz = vec3(0.0);  // Σ over layers of weight × the sample's t
#endif
  for (int l = 0; l < layers; ++l) {
    vec4 pw = texelFetch(gPositionWeight, ivec3(px, l), 0);
    if (pw.w <= 0.0) continue;
    vec3 n = texelFetch(gNormal, ivec3(px, l), 0).xyz;
    vec3 toLight;
    float r = 1.0;
    vec3 e;
    if (lightType == BAKE_LIGHT_DIRECTIONAL) {
      toLight = -lightDirection;
      e = lightIntensity;
    } else {
      vec3 d = lightPosition - pw.xyz;
      r = length(d);
      float window = rangeWindow(r, lightRange);
      if (r <= 0.0 || window == 0.0) continue;
      toLight = d / r;
      vec3 I = lightIntensity;
      if (lightType == BAKE_LIGHT_SPOT) {
        float t = clamp((dot(lightDirection, -toLight) - cosOuter) * spotScale, 0.0, 1.0);
        I *= t * t;
      } else if (lightType == BAKE_LIGHT_IES) {
        I *= iesCandela(-toLight);
      }
      e = I / (r * r) * window;
      if (lightCutoff > 0.0) e *= 1.0 - smoothstep(0.75 * lightCutoff, lightCutoff, r);
    }
    float cosTheta = dot(n, toLight);
    vec3 ng = texelFetch(gGeomNormal, ivec3(px, l), 0).xyz;
    float cosGeom = dot(ng, toLight);  // ≤ 0: the sample's own triangle hides the light
    if (cosTheta <= 0.0 || cosGeom <= 0.0 || max(e.r, max(e.g, e.b)) <= 0.0) continue;
    bool ambiguous;
    vec3 unshadowed = pw.w * e * cosTheta;
    float visible = lit(pw.xyz, n, ng, cosGeom, r, ambiguous);
    sum += unshadowed * visible;
    leak += ambiguous ? dot(unshadowed, vec3(1.0 / 3.0)) : 0.0;  // what the texel gets if the answer is wrong
#ifdef DIRECTIONAL
    // g = E ω (E facing the light), its tangential part for the sample's normal, weighted like the map.
    vec3 g = pw.w * e * visible;
    vec3 t = toLight - cosTheta * n;
    tx += g * t.x;
    ty += g * t.y;
    tz += g * t.z;
#endif
  }
  result = vec4(sum / kPi, leak / kPi);
#ifdef DIRECTIONAL
  l1x = vec4(tx / kPi, 0.0);
  l1y = vec4(ty / kPi, 0.0);
  l1z = vec4(tz / kPi, 0.0);
#endif
}
