// Sampling building blocks shared by the walk and the backends: the Halton sequence (digit-permuted),
// alias tables, warps to triangles, hemispheres and spheres, and a small seeded RNG.
#pragma once
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "common/maths.h"  // channelMean: the scalar weight of an RGB power

namespace irbake {

// Halton sequence: dimension d uses the d-th prime b as base (2, 3, 5, ...), randomized by digit
// permutation: digit position k of dimension d goes through its own seeded random permutation of 0..b−1
// (pbrt-v4's "permute digits"; Owen scrambling restricted to one permutation per digit position). Every
// seed gives a low-discrepancy sequence (each prefix of b^m points stays stratified in every dimension)
// whose every point is uniform over seeds, independently across dimensions. Why not Keller's plain Φ_b:
// unscrambled low dimensions (light choice, start point) with one shared permutation for the direction
// dimensions bias the walk: a region lit through several bounces came out dark for every seed.
class Halton {
 public:
  Halton(int dimensions, uint32_t seed);
  int dimensions() const { return static_cast<int>(primes_.size()); }
  // The index-th point's coordinate in dimension dim, in [0, 1).
  double sample(int dim, uint64_t index) const;

 private:
  std::vector<uint32_t> primes_;
  std::vector<std::vector<uint16_t>> permutations_;  // per dimension: digits_ permutations of 0..b−1, one per
                                                      // digit position
  std::vector<int> digits_;                           // per dimension: digit positions scrambled
};

// Plain radical inverse in base b (Φ_b).
double radicalInverse(uint32_t base, uint64_t index);

// Walker/Vose alias table over non-negative weights: O(1) sampling with one uniform number.
class AliasTable {
 public:
  AliasTable() = default;
  explicit AliasTable(const std::vector<double>& weights);
  bool empty() const { return prob_.empty(); }
  size_t size() const { return prob_.size(); }
  // Picks an index; *residual (optional) receives a fresh uniform number in [0,1) recovered from u,
  // so one QMC coordinate both selects and keeps stratifying (used for the point on the emitter).
  size_t sample(double u, double* residual = nullptr) const;
  double pdf(size_t i) const { return pdf_[i]; }  // probability of index i
  double total() const { return total_; }         // sum of the weights

 private:
  std::vector<double> prob_;
  std::vector<uint32_t> alias_;
  std::vector<double> pdf_;
  double total_ = 0.0;
};

// Orthonormal frame around unit n (Duff et al. 2017).
void orthonormalBasis(const glm::vec3& n, glm::vec3& t, glm::vec3& b);
// Cosine-distributed unit direction around unit n (pdf cosθ/π) from two uniforms.
glm::vec3 cosineHemisphere(const glm::vec3& n, double u, double v);

// The rotated Fibonacci lattice of cosine rays that the per-sample stages trace (the sky, the clamp compensation,
// the final gather): ray i of count at (u, v) = ({(i + ½)/count + r1}, {i/φ + r2}) through cosineHemisphere.
// next() gives rays 0, 1, ... in turn, as cosineHemisphere would up to rounding, but with the frame made once and
// the azimuth turned by a rotation per ray instead of a sine and cosine (the gather traces tens of millions).
class CosineLattice {
 public:
  CosineLattice(const glm::vec3& n, int count, double r1, double r2);
  glm::vec3 next();

 private:
  glm::vec3 n_, t_, b_;
  double r1_, step_;       // u of ray i = {r1 + (i + ½) step}
  double cos_, sin_;       // the azimuth 2π v of the next ray
  int i_ = 0;
};
// Uniform unit direction on the sphere (pdf 1/(4π)).
glm::vec3 uniformSphere(double u, double v);
// Area-uniform barycentrics (b1, b2) on a triangle: p = (1-b1-b2) v0 + b1 v1 + b2 v2.
glm::vec2 uniformTriangle(double u, double v);

// Small counter-based RNG for the Monte Carlo parts (reference, bias compensation): splitmix64.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t nextU64();
  double uniform() { return static_cast<double>(nextU64() >> 11) * (1.0 / 9007199254740992.0); }  // [0,1)

 private:
  uint64_t state_;
};
// Mixes several integers into one well-spread 64-bit seed.
uint64_t hashSeed(uint64_t a, uint64_t b = 0, uint64_t c = 0);

}  // namespace irbake
