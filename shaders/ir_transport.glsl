// Light transport shared by the GL passes; the same formulas as the Embree backend
// (baker/backend/embree/geometry_term.h). A map value is irradiance/π.
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

// Distance along the cube face axis of a direction (the depth a cube face stores).
float cubeAxisDistance(vec3 local) { return max(max(abs(local.x), abs(local.y)), abs(local.z)); }

// Depth bias for a shadow lookup: a constant (scene scale) plus the depth change across one shadow
// texel of footprint `footprint` on a surface tilted by θ (tanθ = sinθ / cosθ, capped).
float shadowBias(float constantBias, float slopeScale, float footprint, float cosTheta) {
  float c = clamp(cosTheta, 0.05, 1.0);
  float tanTheta = sqrt(1.0 - c * c) / c;
  return constantBias + slopeScale * footprint * tanTheta;
}
