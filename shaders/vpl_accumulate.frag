// Accumulation: every texel sample of a page against a batch of VPLs, each with its depth cube (a cube in
// the VPL's normal-aligned frame, reversed-Z: depth = near / axis distance) stored as tiles 5k..5k+4 of
// one 2D depth atlas (gl_resources.h, DepthAtlas: faces +X −X +Y −Y +Z; −Z is never drawn and reads as lit).
// Output: the batch's contribution to irradiance/π, summed by additive blending.
//
// Cost on llvmpipe (8 fragments per SIMD vector, 2 threads) is everything inside the per-VPL loop, so:
// - SHADOW_COMPARE: hardware depth comparison with bilinear filtering (sampler2DArrayShadow, GL_LINEAR,
//   GL_GEQUAL) gives the 2×2 percentage-closer filter in one lookup instead of 4 texelFetch + compares.
// - The lookup point in the cube frame comes from d (receiver → VPL) and cy; no second position.
// - Branch-free body: the hemisphere test selects the result instead of masking a `continue`.
// - LAYERS: the S×S supersample count as a constant (1: no layer loop). Invalid texels never run: the
//   pass is depth-tested against the page's validity mask (gl_backend.cpp).
// - The VPLs come from a buffer texture and the per-bake constants are compiled in (see below).
// The batch loop is not unrolled (constant VPL indices from a uniform block) and the face is chosen by hand,
// not by a cube-map-array sampler: on llvmpipe neither alternative is cheaper.
layout(binding = BAKE_UNIT_POSITION_WEIGHT) uniform sampler2DArray gPositionWeight;  // xyz world position, w coverage weight
layout(binding = BAKE_UNIT_NORMAL) uniform sampler2DArray gNormal;          // xyz unit shading normal
layout(binding = BAKE_UNIT_GEOMETRIC_NORMAL) uniform sampler2DArray gGeomNormal;      // xyz unit normal of the sample's triangle
#if defined(CONTACT_FLAGS)
layout(binding = BAKE_UNIT_VPL_DEPTH) uniform sampler2D vplDepth;        // depth atlas, raw depths (2×2 filter by textureGather)
#ifdef SEE_THROUGH
layout(binding = BAKE_UNIT_VPL_SEE_THROUGH_DEPTH) uniform sampler2D seeThroughDepth;  // the same cubes, see-through primitives only
#endif
#elif defined(SHADOW_COMPARE)
layout(binding = BAKE_UNIT_VPL_DEPTH) uniform sampler2DShadow vplDepth;  // depth atlas, 5 tiles per VPL cube, compare GL_GEQUAL
#else
layout(binding = BAKE_UNIT_VPL_DEPTH) uniform sampler2D vplDepth;        // depth atlas, 5 tiles per VPL cube
#endif

// The batch's VPLs: 3 RGBA32F texels each (gl_resources.h, VplTexels). A buffer texture, not a uniform
// block: the loop index is not known to be uniform, so a block read is a per-lane gather of every
// component (8 scalar loads each), while a texelFetch loads the 4 components of a lane at once.
layout(binding = BAKE_UNIT_VPL_TABLE) uniform samplerBuffer vplTable;
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
#ifdef DIRECTIONAL
// Directional maps (transport/directional.h): the tangential irradiance vector t, world axis k in target
// 1 + k (RGB; alpha unused), summed by the same blending. Only bakes that ask for L1 compile this.
layout(location = 1) out vec4 l1x;
layout(location = 2) out vec4 l1y;
layout(location = 3) out vec4 l1z;
#endif

#ifdef CONTACT_FLAGS
// Receiver-plane check of a biased lookup (contact leaks). The depth bias lets through whatever lies
// within `bias` in front of the receiver: its own surface (why the bias exists) but also a true occluder
// at a contact (a box on a floor, a lamp 0.1 mm under a ceiling, a wall 1 mm behind a cupboard). Each
// of the 2×2 texels the filter counted as lit is put back on its own ray: where the plane of the
// receiver's triangle meets that ray (axis distance nv / (n·w(q))), the stored surface must not lie in
// front of it. Returns the filter weight of texels that fail: the lookup cannot tell a contact from
// the receiver, and the backend resolves the texel with rays (gl_backend.cpp, contact texels).
// n: the receiver triangle's normal in the cube frame; v: the lookup point (cube frame); q0: face
// coordinates (axis-normalised, −1…1) of texel (i0, j0)'s centre; dq: one texel in those units.
float ambiguousWeight(int face, vec3 n, vec3 v, vec4 stored, float reference, vec2 q0, float dq, vec2 f, vec2 ql) {
  // n·w(q) = a0 + q.x·as + q.y·at for the face's direction w(q) (the inverse of the lookup's face table).
  vec3 a = face == 0 ? vec3(n.x, -n.z, -n.y)
         : face == 1 ? vec3(-n.x, n.z, -n.y)
         : face == 2 ? vec3(n.y, n.x, n.z)
         : face == 3 ? vec3(-n.y, n.x, -n.z)
                     : vec3(n.z, n.x, -n.y);
  float nv = dot(n, v);  // < 0: the receiver faces the cube's origin
  // Tolerance: the rasteriser snaps vertices to a sub-texel grid, so a stored plane is off by a small
  // fraction of its depth change across one texel (at the lookup: |∂A/∂q|·dq); 5% of that, plus 1e-5 of
  // the distance for float rounding. A contact nearly face-on (a lamp 0.1 mm under a ceiling lit from
  // below) stays far above it; at grazing angles the slope bias itself is of that order.
  float Dl = a.x + ql.x * a.y + ql.y * a.z;
  float Al = nv / min(Dl, -1e-30);
  float tol = 1e-5 * Al + 0.05 * Al * (abs(a.y) + abs(a.z)) * dq / max(abs(Dl), 1e-30);
  // textureGather order: x (i0, j1), y (i1, j1), z (i1, j0), w (i0, j0).
  vec4 qx = vec4(q0.x, q0.x + dq, q0.x + dq, q0.x);
  vec4 qy = vec4(q0.y + dq, q0.y + dq, q0.y, q0.y);
  vec4 D = a.x + qx * a.y + qy * a.z;
  // The plane's axis distance on each texel's ray (a ray that never meets it: infinitely far), and the
  // stored surface's (near / s).
  vec4 planeDepth = mix(vec4(3.0e38), nv / min(D, vec4(-1e-30)), lessThan(D, vec4(0.0)));
  vec4 storedDepth = nearPlane / max(stored, vec4(1e-30));
  bvec4 litTexel = lessThanEqual(stored, vec4(reference));
  bvec4 drawn = greaterThan(stored, vec4(0.0));
  vec4 inFront = vec4(lessThan(storedDepth, planeDepth - tol));
  vec4 amb = vec4(litTexel) * vec4(drawn) * inFront;
  vec4 w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
  return dot(amb, w);
}
#endif

// Fraction of the lookup point (local: relative to the cube's origin, in its frame) that sees the
// cube's centre, 2×2 percentage-closer filtered (or a single texel without SHADOW_PCF).
float vplVisibility(int cube, vec3 v, float bias, vec3 nLocal, out float ambiguous) {
  ambiguous = 0.0;
  vec3 a = abs(v);
  bool xMajor = a.x >= a.y && a.x >= a.z;
  bool yMajor = !xMajor && a.y >= a.z;
  float axisDistance = xMajor ? a.x : (yMajor ? a.y : a.z);
  int face = xMajor ? (v.x >= 0.0 ? 0 : 1) : (yMajor ? (v.y >= 0.0 ? 2 : 3) : (v.z >= 0.0 ? 4 : 5));
  vec2 sctc = xMajor ? vec2(v.x >= 0.0 ? -v.z : v.z, -v.y)
                     : (yMajor ? vec2(v.x, v.y >= 0.0 ? v.z : -v.z) : vec2(v.z >= 0.0 ? v.x : -v.x, -v.y));
#ifdef CONTACT_FLAGS
  // As SHADOW_COMPARE below, with the 2×2 filter done by hand on textureGather's raw depths, so that
  // every texel the bias lets through is checked against the receiver's plane (ambiguousWeight).
  float ax = axisDistance - bias;
  float inv = 1.0 / (axisDistance * ax);
  if (face == 5) return 1.0;
  if (ax <= nearPlane) {  // the receiver lies within the bias of the cube's origin: unresolvable
    ambiguous = 1.0;
    return 1.0;
  }
  float reference = nearPlane * axisDistance * inv;
  vec2 t = clamp(sctc * (0.5 * faceSize * ax * inv) + 0.5 * faceSize, vec2(0.5), vec2(faceSize - 0.5));
  // The 2×2 texels are picked here (i0 = floor(t − 0.5)) and gathered at their shared corner, where the
  // sampler's own rounding of the coordinate (8 sub-texel bits on llvmpipe) cannot pick other ones.
  vec2 st = t - 0.5;
  vec2 i0 = floor(st);
  vec2 f = st - i0;
  vec4 stored = textureGather(vplDepth, (i0 + 1.0 + vec2(tileOrigin(cube, face))) * atlasInvSize);
  vec4 litTexel = vec4(lessThanEqual(stored, vec4(reference)));
  float visibility = mix(mix(litTexel.w, litTexel.z, f.x), mix(litTexel.x, litTexel.y, f.x), f.y);
  if (visibility > 0.0) {
    float dq = 2.0 / faceSize;
    vec2 q0 = (i0 + 0.5) * dq - 1.0;
    ambiguous = ambiguousWeight(face, nLocal, v, stored, reference, q0, dq, f, sctc / axisDistance);
#ifdef SEE_THROUGH
    // A see-through surface in front of the receiver (beyond the bias) on a lit texel: its transmittance,
    // or its MASK hole, is for the rays to find.
    vec4 glass = textureGather(seeThroughDepth, (i0 + 1.0 + vec2(tileOrigin(cube, face))) * atlasInvSize);
    vec4 w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
    ambiguous = max(ambiguous, dot(litTexel * vec4(greaterThan(glass, vec4(reference))), w));
#endif
  }
  return visibility;
#elif defined(SHADOW_COMPARE)
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
vec3 vplTerm(Vpl v, int cube, vec3 x, vec3 nx, vec3 ng, float noClamp, inout float leak) {
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
  vec3 nLocal = vec3(dot(ng, v.tangent), dot(ng, v.bitangent), dot(ng, v.normal));
  float ambiguous;
  float visibility = vplVisibility(cube, local, bias, nLocal, ambiguous);
  // Selected, not multiplied: behind either surface the lookup may be meaningless (even NaN).
  bool front = cx > 0.0 && cy > 0.0 && cg > 0.0;
  leak += front ? dot(v.power, vec3(1.0 / 3.0)) * g * ambiguous : 0.0;
  return front ? v.power * (g * visibility) : vec3(0.0);
}

void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 sum = vec3(0.0);
  float leak = 0.0;
#ifdef DIRECTIONAL
  vec3 tx = vec3(0.0), ty = vec3(0.0), tz = vec3(0.0);  // Σ over layers of weight × the sample's t
#endif
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
    float sampleLeak = 0.0;
#ifdef DIRECTIONAL
    // The sample's irradiance vector g = Σ E_i ω_i (per world axis, RGB), E_i facing the VPL: a term is
    // E_i cosθx, and ω_i = d / r with cosθx = cx / r, so E_i ω_i = (term / cx) · d (as the Embree backend).
    vec3 gx = vec3(0.0), gy = vec3(0.0), gz = vec3(0.0);
    for (int k = 0; k < vplCount; ++k) {
      Vpl v = loadVpl(k);
      vec3 term = vplTerm(v, k, x, nx, ng, noClamp, sampleLeak);
      s += term;
      vec3 d = v.position - x;  // the same d and cx as vplTerm's (the compiler shares them)
      float cx = dot(nx, d);
      vec3 e = term * (cx > 0.0 ? 1.0 / cx : 0.0);  // term is 0 wherever cx ≤ 0 (selected in vplTerm)
      gx += e * d.x;
      gy += e * d.y;
      gz += e * d.z;
    }
    // Its tangential part t = g − (g·nx) nx, per channel (tangentialPart); weighted like the map.
    vec3 gn = gx * nx.x + gy * nx.y + gz * nx.z;
    float wl = pw.w > 0.0 ? pw.w : 0.0;
    tx += wl * (gx - gn * nx.x);
    ty += wl * (gy - gn * nx.y);
    tz += wl * (gz - gn * nx.z);
#else
    for (int k = 0; k < vplCount; ++k) s += vplTerm(loadVpl(k), k, x, nx, ng, noClamp, sampleLeak);
#endif
    sum += pw.w > 0.0 ? pw.w * s : vec3(0.0);
    leak += pw.w > 0.0 ? pw.w * sampleLeak : 0.0;
  }
  // alpha: the channel-mean light that lookups let through without being able to tell a contact from
  // the receiver (CONTACT_FLAGS; 0 otherwise), in map units like rgb.
  result = vec4(sum * kInvPi2, leak * kInvPi2);
#ifdef DIRECTIONAL
  l1x = vec4(tx * kInvPi2, 0.0);
  l1y = vec4(ty * kInvPi2, 0.0);
  l1z = vec4(tz * kInvPi2, 0.0);
#endif
}
