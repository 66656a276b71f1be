#include "sampling/sampling.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "common/maths.h"

namespace irbake {

namespace {

std::vector<uint32_t> firstPrimes(int count) {
  std::vector<uint32_t> primes;
  for (uint32_t n = 2; static_cast<int>(primes.size()) < count; ++n) {
    bool prime = true;
    for (uint32_t p : primes) {
      if (p * p > n) break;
      if (n % p == 0) { prime = false; break; }
    }
    if (prime) primes.push_back(n);
  }
  return primes;
}
}  // namespace

uint64_t Rng::nextU64() {
  uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

uint64_t hashSeed(uint64_t a, uint64_t b, uint64_t c) {
  Rng r(a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull) * 0xC2B2AE3D27D4EB4Full ^ (c + 0x165667B19E3779F9ull));
  r.nextU64();
  return r.nextU64();
}

double radicalInverse(uint32_t base, uint64_t index) {
  const double inv = 1.0 / base;
  double f = inv, r = 0.0;
  while (index > 0) {
    r += static_cast<double>(index % base) * f;
    index /= base;
    f *= inv;
  }
  return r;
}

Halton::Halton(int dimensions, uint32_t seed) : primes_(firstPrimes(std::max(dimensions, 2))) {
  permutations_.resize(primes_.size());
  digits_.resize(primes_.size());
  for (size_t d = 0; d < primes_.size(); ++d) {
    const uint32_t b = primes_[d];
    // Enough digits for any 64-bit index and for double precision: b^-digits < 2^-53.
    const int digits = static_cast<int>(std::ceil(64.0 * std::log(2.0) / std::log(static_cast<double>(b)))) + 1;
    digits_[d] = digits;
    std::vector<uint16_t>& perms = permutations_[d];
    perms.resize(static_cast<size_t>(digits) * b);
    for (int k = 0; k < digits; ++k) {
      uint16_t* perm = &perms[static_cast<size_t>(k) * b];
      std::iota(perm, perm + b, uint16_t(0));
      Rng rng(hashSeed(seed, d, 0x4A170000ull + static_cast<uint64_t>(k)));
      for (uint32_t i = b - 1; i >= 1; --i) {  // Fisher–Yates over all b digits
        const uint32_t j = static_cast<uint32_t>(rng.nextU64() % (i + 1));
        std::swap(perm[i], perm[j]);
      }
    }
  }
}

double Halton::sample(int dim, uint64_t index) const {
  const uint32_t base = primes_[dim];
  const uint16_t* perm = permutations_[dim].data();
  const double inv = 1.0 / base;
  double f = inv, r = 0.0;
  // Every digit position, the index's leading zeros included (they are permuted too), so the point is a
  // uniform number whatever the index's length.
  for (int k = 0; k < digits_[dim]; ++k, perm += base) {
    r += perm[index % base] * f;
    index /= base;
    f *= inv;
  }
  return std::min(r, 0.99999999999999989);
}

AliasTable::AliasTable(const std::vector<double>& weights) {
  size_t n = weights.size();
  if (n == 0) return;
  total_ = 0.0;
  for (double w : weights) total_ += std::max(0.0, w);
  prob_.assign(n, 1.0);
  alias_.resize(n);
  pdf_.resize(n);
  std::iota(alias_.begin(), alias_.end(), 0u);
  if (total_ <= 0.0) {  // all zero: uniform
    std::fill(pdf_.begin(), pdf_.end(), 1.0 / n);
    return;
  }
  std::vector<double> scaled(n);
  std::vector<uint32_t> small, large;
  for (size_t i = 0; i < n; ++i) {
    pdf_[i] = std::max(0.0, weights[i]) / total_;
    scaled[i] = pdf_[i] * n;
    (scaled[i] < 1.0 ? small : large).push_back(static_cast<uint32_t>(i));
  }
  while (!small.empty() && !large.empty()) {
    uint32_t s = small.back(), l = large.back();
    small.pop_back();
    prob_[s] = scaled[s];
    alias_[s] = l;
    scaled[l] = (scaled[l] + scaled[s]) - 1.0;
    if (scaled[l] < 1.0) {
      large.pop_back();
      small.push_back(l);
    }
  }
  for (uint32_t i : large) prob_[i] = 1.0;  // round-off leftovers
  for (uint32_t i : small) prob_[i] = 1.0;
}

size_t AliasTable::sample(double u, double* residual) const {
  size_t n = prob_.size();
  double x = u * static_cast<double>(n);
  size_t k = std::min(static_cast<size_t>(x), n - 1);
  double frac = std::clamp(x - static_cast<double>(k), 0.0, 1.0);
  if (frac < prob_[k]) {
    if (residual) *residual = std::min(frac / prob_[k], 0.99999999999999989);
    return k;
  }
  if (residual) *residual = std::min((frac - prob_[k]) / (1.0 - prob_[k]), 0.99999999999999989);
  return alias_[k];
}

void orthonormalBasis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float c = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x);
  b = glm::vec3(c, sign + n.y * n.y * a, -n.y);
}

glm::vec3 cosineHemisphere(const glm::vec3& n, double u, double v) {
  double r = std::sqrt(u), phi = 2.0 * kPi * v;
  double z = std::sqrt(std::max(0.0, 1.0 - u));
  glm::vec3 t, b;
  orthonormalBasis(n, t, b);
  return glm::normalize(t * float(r * std::cos(phi)) + b * float(r * std::sin(phi)) + n * float(z));
}

namespace {
constexpr double kInverseGolden = 0.6180339887498949;  // 1/φ: the lattice's azimuth step, in turns
}  // namespace

CosineLattice::CosineLattice(const glm::vec3& n, int count, double r1, double r2)
    : n_(n), r1_(r1), step_(1.0 / std::max(1, count)), cos_(std::cos(2.0 * kPi * r2)), sin_(std::sin(2.0 * kPi * r2)) {
  orthonormalBasis(n, t_, b_);
}

glm::vec3 CosineLattice::next() {
  static const double kTurnCos = std::cos(2.0 * kPi * kInverseGolden), kTurnSin = std::sin(2.0 * kPi * kInverseGolden);
  double u = r1_ + (i_ + 0.5) * step_;  // < 2: one wrap at most
  if (u >= 1.0) u -= 1.0;
  const double r = std::sqrt(u), z = std::sqrt(std::max(0.0, 1.0 - u));
  const glm::vec3 dir = glm::normalize(t_ * float(r * cos_) + b_ * float(r * sin_) + n_ * float(z));
  const double c = cos_ * kTurnCos - sin_ * kTurnSin;
  sin_ = sin_ * kTurnCos + cos_ * kTurnSin;
  cos_ = c;
  ++i_;
  return dir;
}

glm::vec3 uniformSphere(double u, double v) {
  double z = 1.0 - 2.0 * u, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * v;
  return glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z));
}

glm::vec2 uniformTriangle(double u, double v) {
  double su = std::sqrt(u);
  return glm::vec2(float(su * (1.0 - v)), float(su * v));
}

}  // namespace irbake
