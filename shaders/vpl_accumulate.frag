// Accumulation: every texel sample of a page against a batch of VPLs, each with its depth cube (a cube in
// the VPL's normal-aligned frame, reversed-Z: depth = near / axis distance) stored as tiles 5k..5k+4 of
// one 2D depth atlas (gl_backend.cpp, DepthAtlas: faces +X −X +Y −Y +Z; −Z is never drawn and reads as lit).
// Output: the batch's contribution to irradiance/π, summed by additive blending.
//
// Cost on llvmpipe (8 fragments per SIMD vector, 2 threads) is everything inside the per-VPL loop, so
// (docs/performance.md, "What limits the per-VPL cost"):
// - SHADOW_COMPARE: hardware depth comparison with bilinear filtering (sampler2DArrayShadow, GL_LINEAR,
//   GL_GEQUAL) gives the 2×2 percentage-closer filter in one lookup instead of 4 texelFetch + compares.
// - The lookup point in the cube frame comes from d (receiver → VPL) and cy; no second position.
// - Branch-free body: the hemisphere test selects the result instead of masking a `continue`.
// - LAYERS: the S×S supersample count as a constant (1: no layer loop). Invalid texels never run: the
//   pass is depth-tested against the page's validity mask (gl_backend.cpp).
// - The VPLs come from a buffer texture and the per-bake constants are compiled in (see below).
// Measured and dropped: unrolling the batch (constant VPL indices from a uniform block: 2× slower), a
// cube-map-array sampler doing the face selection (no faster).
layout(binding = 0) uniform sampler2DArray gPositionWeight;  // xyz world position, w coverage weight
layout(binding = 1) uniform sampler2DArray gNormal;          // xyz unit shading normal
layout(binding = 4) uniform sampler2DArray gGeomNormal;      // xyz unit normal of the sample's triangle
#if defined(SHADOW_COMPARE)
layout(binding = 2) uniform sampler2DShadow vplDepth;  // depth atlas, 5 tiles per VPL cube, compare GL_GEQUAL
#else
layout(binding = 2) uniform sampler2D vplDepth;        // depth atlas, 5 tiles per VPL cube
#endif

// The batch's VPLs: 3 RGBA32F texels each (gl_backend.cpp, VplTexels). A buffer texture, not a uniform
// block: the loop index is not known to be uniform, so a block read is a per-lane gather of every
// component (8 scalar loads each), while a texelFetch loads the 4 components of a lane at once.
layout(binding = 3) uniform samplerBuffer vplTable;
struct Vpl {
  vec3 position;   // geometry term
  vec3 normal;     // unit normal = local +Z of its cube
  vec3 power;      // Φ (W)
  vec3 tangent;    // local +X
  vec3 bitangent;  // local +Y = normal × tangent (as vplFrame builds it)
};
Vpl loadVpl(int k) {
  vec4 a = texelFetch(vplTable, 3 * k), b = texelFetch(vplTable, 3 * k + 1), c = texelFetch(vplTable, 3 * k + 2);
  return Vpl(a.xyz, b.xyz, vec3(a.w, b.w, c.w), c.xyz, cross(b.xyz, c.xyz));
}

uniform int vplCount;          // VPLs in this batch
uniform int layers;            // S×S supersample layers (when LAYERS is not defined)
// Per-bake constants, compiled in (exact float literals from the host): a uniform read inside the VPL
// loop costs llvmpipe a per-lane gather, a constant costs nothing and folds.
const float clampBound = CLAMP_BOUND;       // geometry-term clamp (1/m²), ≤ 0: none
const float nearPlane = NEAR_PLANE;         // cube near plane (m)
const float constantBias = CONSTANT_BIAS;   // m
const float slopeBias = SLOPE_BIAS;         // in shadow texels
const float normalOffset = NORMAL_OFFSET;   // in shadow texels
const float texelAngle = TEXEL_ANGLE;       // angular size of one cube texel at the face centre (2 / faceSize)
const float originOffset = ORIGIN_OFFSET;   // VPL shadow origin = position + originOffset·normal (m)
const float faceSize = FACE_SIZE;           // cube face tile size (texels)
const int atlasCols = ATLAS_COLS;           // tiles per atlas row
const vec2 atlasInvSize = vec2(ATLAS_INV_WIDTH, ATLAS_INV_HEIGHT);

// Texel origin of a cube face's tile in the atlas (face 5, −Z, maps onto +Z; callers treat it as lit).
ivec2 tileOrigin(int cube, int face) {
#if ATLAS_COLS == 5
  return ivec2(min(face, 4), cube) * int(faceSize);  // one cube per row
#else
  int t = 5 * cube + min(face, 4);
  return ivec2(t % atlasCols, t / atlasCols) * int(faceSize);
#endif
}

layout(location = 0) out vec4 result;

// Fraction of the lookup point (local: relative to the cube's origin, in its frame) that sees the
// cube's centre, 2×2 percentage-closer filtered (or a single texel without SHADOW_PCF).
float vplVisibility(int cube, vec3 v, float bias) {
  vec3 a = abs(v);
  bool xMajor = a.x >= a.y && a.x >= a.z;
  bool yMajor = !xMajor && a.y >= a.z;
  float axisDistance = xMajor ? a.x : (yMajor ? a.y : a.z);
  int face = xMajor ? (v.x >= 0.0 ? 0 : 1) : (yMajor ? (v.y >= 0.0 ? 2 : 3) : (v.z >= 0.0 ? 4 : 5));
  vec2 sctc = xMajor ? vec2(v.x >= 0.0 ? -v.z : v.z, -v.y)
                     : (yMajor ? vec2(v.x, v.y >= 0.0 ? v.z : -v.z) : vec2(v.z >= 0.0 ? v.x : -v.x, -v.y));
#ifdef SHADOW_COMPARE
  // lit where stored ≤ near / (axis − bias) (reversed-Z); axis ≤ bias: always lit (reference 1 ≥ any depth).
  // One division for both 1/axis and 1/(axis − bias); where axis − bias ≤ near the reference is 1 and
  // the coordinates do not matter. The −Z face (below the VPL's surface, never drawn) is lit.
  float ax = axisDistance - bias;
  float inv = 1.0 / (axisDistance * ax);
  float reference = (ax > nearPlane && face < 5) ? nearPlane * axisDistance * inv : 1.0;
  // Face coordinates in texels, clamped half a texel inside the tile: the 2×2 filtered compare then
  // never reads a neighbouring tile (at the clamp the outer texel's weight is 0; the old layered
  // lookup's GL_CLAMP_TO_EDGE gave the same edge texel).
  vec2 t = clamp(sctc * (0.5 * faceSize * ax * inv) + 0.5 * faceSize, vec2(0.5), vec2(faceSize - 0.5));
  return texture(vplDepth, vec3((t + vec2(tileOrigin(cube, face))) * atlasInvSize, reference));
#elif defined(SHADOW_PCF)
  // 2×2 percentage-closer filter by 4 texelFetch (texel indices clamped to the tile).
  int size = int(faceSize);
  vec2 st = (sctc / axisDistance * 0.5 + 0.5) * faceSize - 0.5;
  vec2 f = fract(st);
  ivec2 t0 = clamp(ivec2(floor(st)), ivec2(0), ivec2(size - 1));
  ivec2 t1 = min(t0 + 1, ivec2(size - 1));
  ivec2 o = tileOrigin(cube, face);
  vec4 d = vec4(texelFetch(vplDepth, o + t0, 0).r, texelFetch(vplDepth, o + ivec2(t1.x, t0.y), 0).r,
                texelFetch(vplDepth, o + ivec2(t0.x, t1.y), 0).r, texelFetch(vplDepth, o + t1, 0).r);
  d = face < 5 ? d : vec4(0.0);
  vec4 lit = vec4(lessThanEqual(axisDistance * d, vec4(nearPlane) + bias * d));
  return mix(mix(lit.x, lit.y, f.x), mix(lit.z, lit.w, f.x), f.y);
#else
  int size = int(faceSize);
  ivec2 texel = clamp(ivec2((sctc / axisDistance * 0.5 + 0.5) * faceSize), ivec2(0), ivec2(size - 1));
  float depth = face < 5 ? texelFetch(vplDepth, tileOrigin(cube, face) + texel, 0).r : 0.0;
  return cubeLit(depth, axisDistance, nearPlane, bias) ? 1.0 : 0.0;
#endif
}

// One VPL's unweighted contribution (Φ G V, before 1/π²) at receiver x with shading normal nx and
// geometric normal ng. The cosine is the shading normal's; the depth bias follows the triangle the cube
// sampled (ng), and a receiver whose own triangle faces away from the VPL is in its own shadow (as the
// ray tracer finds: its shadow ray crosses that triangle first).
vec3 vplTerm(Vpl v, int cube, vec3 x, vec3 nx, vec3 ng, float noClamp) {
  vec3 d = v.position - x;  // receiver → VPL
  float cx = dot(nx, d), cy = -dot(v.normal, d), cg = dot(ng, d);
  float r2 = dot(d, d);
  float g = min(cx * cy / (r2 * r2), noClamp);  // vplGeometryTerm, inlined
  float r = sqrt(r2);
  float footprint = r * texelAngle;
  // Lookup point in the cube's frame, relative to the shadow origin (VPL + w·normal): −d − w·ny, whose
  // z is cy − w; optionally pushed along the receiver normal.
  vec3 local = vec3(-dot(d, v.tangent), -dot(d, v.bitangent), cy - originOffset);
#ifdef HAS_NORMAL_OFFSET
  vec3 o = nx * (normalOffset * footprint);
  local += vec3(dot(o, v.tangent), dot(o, v.bitangent), dot(o, v.normal));
#endif
  float bias = shadowBiasTan(constantBias, slopeBias, footprint, sqrt(max(r2 - cg * cg, 0.0)) / cg);
  float visibility = vplVisibility(cube, local, bias);
  // Selected, not multiplied: behind either surface the lookup may be meaningless (even NaN).
  return (cx > 0.0 && cy > 0.0 && cg > 0.0) ? v.power * (g * visibility) : vec3(0.0);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 sum = vec3(0.0);
  float noClamp = clampBound > 0.0 ? clampBound : 3.0e38;
#ifdef LAYERS
  const int layerCount = LAYERS;
#else
  int layerCount = layers;
#endif
  for (int l = 0; l < layerCount; ++l) {
    vec4 pw = texelFetch(gPositionWeight, ivec3(p, l), 0);
    vec3 x = pw.xyz;
    vec3 nx = texelFetch(gNormal, ivec3(p, l), 0).xyz;
    vec3 ng = texelFetch(gGeomNormal, ivec3(p, l), 0).xyz;
    vec3 s = vec3(0.0);
    for (int k = 0; k < vplCount; ++k) s += vplTerm(loadVpl(k), k, x, nx, ng, noClamp);
    sum += pw.w > 0.0 ? pw.w * s : vec3(0.0);
  }
  result = vec4(sum * kInvPi2, 0.0);
}
