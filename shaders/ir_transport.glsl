// Light transport shared by the GL passes; the same formulas as the Embree backend
// (baker/transport/geometry_term.h). A map value is irradiance/π.
const float kPi = 3.14159265358979;
const float kInvPi2 = 1.0 / (kPi * kPi);

// Clamped VPL geometry term cosθx cosθy / r² (1/m²); clampBound ≤ 0 disables the clamp.
// d: receiver → VPL (unnormalised), nx: receiver normal, ny: VPL normal.
float vplGeometryTerm(vec3 d, vec3 nx, vec3 ny, float clampBound) {
  float r2 = dot(d, d);
  float cx = dot(nx, d);
  float cy = -dot(ny, d);
  if (cx <= 0.0 || cy <= 0.0 || r2 <= 0.0) return 0.0;
  float g = cx * cy / (r2 * r2);
  return clampBound > 0.0 ? min(g, clampBound) : g;
}

// The GL cube-map face table (OpenGL 4.5 table 8.19) for a lookup vector v: its face (+X −X +Y −Y +Z −Z),
// the face coordinates (sc, tc) before division, and the major-axis distance |ma|.
void cubeFaceCoords(vec3 v, out int face, out vec2 sctc, out float axisDistance) {
  vec3 a = abs(v);
  bool xMajor = a.x >= a.y && a.x >= a.z;
  bool yMajor = !xMajor && a.y >= a.z;
  axisDistance = xMajor ? a.x : (yMajor ? a.y : a.z);
  face = xMajor ? (v.x >= 0.0 ? 0 : 1) : (yMajor ? (v.y >= 0.0 ? 2 : 3) : (v.z >= 0.0 ? 4 : 5));
  sctc = xMajor ? vec2(v.x >= 0.0 ? -v.z : v.z, -v.y)
                : (yMajor ? vec2(v.x, v.y >= 0.0 ? v.z : -v.z) : vec2(v.z >= 0.0 ? v.x : -v.x, -v.y));
}

// Depth cubes are stored as 6 layers of a 2D array per cube (GL face order +X −X +Y −Y +Z −Z) and
// looked up by hand with the GL cube-map face table (OpenGL 4.5 table 8.19): on llvmpipe a texelFetch
// is cheaper than a cube-array sample. Returns the stored reversed-Z depth (near / occluder axis
// distance; 0 where nothing was drawn) and the lookup point's own axis distance in axisDistance.
float cubeDepth(sampler2DArray cubes, int cube, vec3 v, out float axisDistance) {
  int face;
  vec2 sctc;
  cubeFaceCoords(v, face, sctc, axisDistance);
  int size = textureSize(cubes, 0).x;
  ivec2 texel = clamp(ivec2((sctc / axisDistance * 0.5 + 0.5) * float(size)), ivec2(0), ivec2(size - 1));
  return texelFetch(cubes, ivec3(texel, 6 * cube + face), 0).r;
}

// The direction (axis component ±1) of the centre of the cube texel that the lookup point v reads in
// cubeDepth: the inverse of the face table, so a stored depth can be put back where it was rendered.
vec3 cubeTexelCentreDirection(vec3 v, int size) {
  int face;
  vec2 sctc;
  float axisDistance;
  cubeFaceCoords(v, face, sctc, axisDistance);
  ivec2 texel = clamp(ivec2((sctc / axisDistance * 0.5 + 0.5) * float(size)), ivec2(0), ivec2(size - 1));
  vec2 q = (vec2(texel) + 0.5) / float(size) * 2.0 - 1.0;
  return face == 0 ? vec3(1.0, -q.y, -q.x)
       : face == 1 ? vec3(-1.0, -q.y, q.x)
       : face == 2 ? vec3(q.x, 1.0, q.y)
       : face == 3 ? vec3(q.x, -1.0, -q.y)
       : face == 4 ? vec3(q.x, -q.y, 1.0)
                   : vec3(-q.x, -q.y, -1.0);
}

// Fraction of a 2×2 texel neighbourhood (bilinear weights, percentage-closer filtering) that lets
// the lookup point v see the cube's centre: shadow edges become fractional instead of one texel of
// all-or-nothing, which halves the edge error against ray-traced visibility at the same map size.
float cubeVisibilityPcf(sampler2DArray cubes, int cube, vec3 v, float nearPlane, float bias) {
  int face;
  vec2 sctc;
  float axisDistance;
  cubeFaceCoords(v, face, sctc, axisDistance);
  int size = textureSize(cubes, 0).x;
  vec2 st = (sctc / axisDistance * 0.5 + 0.5) * float(size) - 0.5;
  vec2 f = fract(st);
  ivec2 t0 = clamp(ivec2(floor(st)), ivec2(0), ivec2(size - 1));
  ivec2 t1 = min(t0 + 1, ivec2(size - 1));
  int layer = 6 * cube + face;
  vec4 d = vec4(texelFetch(cubes, ivec3(t0.x, t0.y, layer), 0).r, texelFetch(cubes, ivec3(t1.x, t0.y, layer), 0).r,
                texelFetch(cubes, ivec3(t0.x, t1.y, layer), 0).r, texelFetch(cubes, ivec3(t1.x, t1.y, layer), 0).r);
  // lit where axis·depth ≤ near + bias·depth (reversed-Z, no division)
  vec4 lit = vec4(lessThanEqual(axisDistance * d, vec4(nearPlane) + bias * d));
  return mix(mix(lit.x, lit.y, f.x), mix(lit.z, lit.w, f.x), f.y);
}

// Lit test against reversed-Z depth without a division: axis ≤ near/depth + bias.
bool cubeLit(float depth, float axisDistance, float nearPlane, float bias) {
  return axisDistance * depth <= nearPlane + bias * depth;
}

// Depth bias for a shadow lookup: a constant (scene scale) plus the change of stored depth across
// one shadow texel of angular footprint `footprint` (m at the receiver's distance). The stored depth is
// the distance along the face axis, so it varies both with the receiver's tilt θ to the ray (tanθ) and
// with the ray's angle to the face axis (≤ 54.7° in a cube face: tan ≤ √2, hence the + 1.5).
float shadowBiasTan(float constantBias, float slopeScale, float footprint, float tanTheta) {
  return constantBias + slopeScale * footprint * (min(tanTheta, 20.0) + 1.5);
}
float shadowBias(float constantBias, float slopeScale, float footprint, float cosTheta) {
  float c = clamp(cosTheta, 0.05, 1.0);
  return shadowBiasTan(constantBias, slopeScale, footprint, sqrt(1.0 - c * c) / c);
}
