// The exact emitters of IRBAKE_light_probes at a probe-lit surface point (docs/export.md, `emitters`;
// baker/lightmap/polygon_irradiance.h, probe_emitter_field.h): per triangle, Lambert's polygon formula
// E/L = |Σ_e Θ_e (γ_e · n)| / 2 over the triangle clipped to the half-space above the tangent plane (front faces
// only), times its emitter's radiance (Le/π) and visibility v + offset·∇v, clamped to [0, 1].
// EMITTER_TRIANGLES (defined by the program) sizes the arrays; 0 leaves this out.
#if EMITTER_TRIANGLES > 0
uniform vec3 uEmitterPositions[3 * EMITTER_TRIANGLES];  // world-space triangle list
uniform vec3 uEmitterRadiance[EMITTER_TRIANGLES];       // each triangle's emitter's Le/π
uniform vec4 uEmitterVisibility[EMITTER_TRIANGLES];     // its visibility at the object's centre, ∂v/∂x, ∂v/∂y, ∂v/∂z

float triangleIrradianceFactor(vec3 a, vec3 b, vec3 c, vec3 p, vec3 n) {
  if (!(dot(p - a, cross(b - a, c - a)) > 0.0)) return 0.0;
  vec3 tri[3] = vec3[3](a - p, b - p, c - p);
  vec3 poly[4];
  int m = 0;
  for (int i = 0; i < 3; ++i) {
    vec3 u = tri[i], v = tri[(i + 1) % 3];
    float du = dot(u, n), dv = dot(v, n);
    if (du >= 0.0) poly[m++] = u;
    if ((du >= 0.0) != (dv >= 0.0)) poly[m++] = u + (v - u) * (du / (du - dv));
  }
  if (m < 3) return 0.0;
  float sum = 0.0;
  for (int i = 0; i < m; ++i) {
    vec3 u = poly[i], v = poly[(i + 1) % m], cr = cross(u, v);
    float s = length(cr);
    if (s > 0.0) sum += atan(s, dot(u, v)) / s * dot(cr, n);
  }
  return 0.5 * abs(sum);
}

// E/π at p (normal n, unit) from every exact emitter; `offset` = p − the object's centre.
vec3 exactEmitterLight(vec3 p, vec3 n, vec3 offset) {
  vec3 sum = vec3(0.0);
  for (int t = 0; t < EMITTER_TRIANGLES; ++t) {
    vec4 v = uEmitterVisibility[t];
    float visibility = clamp(v.x + dot(offset, v.yzw), 0.0, 1.0);
    sum += visibility * uEmitterRadiance[t] *
           triangleIrradianceFactor(uEmitterPositions[3 * t], uEmitterPositions[3 * t + 1], uEmitterPositions[3 * t + 2], p, n);
  }
  return sum;
}
#endif
