// The exact irradiance of a uniform Lambertian emitting triangle at a point (Lambert's polygon formula): with
// r_i the vertices relative to the point p, Θ_e the angle edge (r_i, r_i+1) subtends and γ_e the unit normal of
// the plane through p and that edge, E(p, n) = L/2 · |Σ_e Θ_e (γ_e · n)|, the triangle first clipped to the
// half-space above p's tangent plane (so a triangle that straddles the horizon counts only above it). Emission
// leaves the front face only (counter-clockwise, as glTF): a point behind the triangle's plane gets nothing.
// The same math is in shaders/probe_emitters.glsl and runtime/web/irbake_probe_emitters.js.
#pragma once
#include <array>
#include <cmath>

#include <glm/glm.hpp>

namespace irbake {

// Σ_e Θ_e (γ_e · n) / 2 for the triangle (a, b, c) seen from p, facing n (unit): the irradiance over the radiance,
// E/L (= π × the form factor). 0 behind the triangle or when it lies wholly below the tangent plane.
inline float triangleIrradianceFactor(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& p,
                                      const glm::vec3& n) {
  const glm::vec3 front = glm::cross(b - a, c - a);
  if (!(glm::dot(p - a, front) > 0.0f)) return 0.0f;
  // Sutherland–Hodgman against the plane (x − p)·n ≥ 0: at most 4 vertices.
  const std::array<glm::vec3, 3> tri = {a - p, b - p, c - p};
  std::array<glm::vec3, 4> poly;
  int m = 0;
  for (int i = 0; i < 3; ++i) {
    const glm::vec3 &u = tri[i], &v = tri[(i + 1) % 3];
    const float du = glm::dot(u, n), dv = glm::dot(v, n);
    if (du >= 0.0f) poly[m++] = u;
    if ((du >= 0.0f) != (dv >= 0.0f)) poly[m++] = u + (v - u) * (du / (du - dv));
  }
  if (m < 3) return 0.0f;
  float sum = 0.0f;
  for (int i = 0; i < m; ++i) {
    const glm::vec3 &u = poly[i], &v = poly[(i + 1) % m];
    const glm::vec3 cr = glm::cross(u, v);
    const float s = glm::length(cr);
    if (!(s > 0.0f)) continue;  // a zero-length edge or one through p: no angle
    sum += std::atan2(s, glm::dot(u, v)) / s * glm::dot(cr, n);
  }
  return 0.5f * std::abs(sum);
}

// The solid angle of the triangle (a, b, c) from p (Van Oosterom & Strackee 1983), 0 behind it (front face only):
// the mean over every normal n of triangleIrradianceFactor is Ω/4.
inline float triangleSolidAngle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& p) {
  if (!(glm::dot(p - a, glm::cross(b - a, c - a)) > 0.0f)) return 0.0f;
  const glm::vec3 r1 = a - p, r2 = b - p, r3 = c - p;
  const float l1 = glm::length(r1), l2 = glm::length(r2), l3 = glm::length(r3);
  const float num = std::abs(glm::dot(r1, glm::cross(r2, r3)));
  const float den = l1 * l2 * l3 + glm::dot(r1, r2) * l3 + glm::dot(r1, r3) * l2 + glm::dot(r2, r3) * l1;
  return 2.0f * std::atan2(num, den);
}

}  // namespace irbake
