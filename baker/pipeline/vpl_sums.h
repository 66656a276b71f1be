// The VPL part of a bake as a sum of fixed blocks of VPLs, added exactly: the order in which blocks are
// added (threads, shards on other machines, a resumed bake) cannot change a single bit of the result.
//
// Floating-point addition is not associative, so a float or double sum of the blocks would depend on how
// the VPL range was split. Each block's map value (a float) is instead converted to fixed point with
// 64 fractional bits in a 128-bit integer: the conversion is exact for every float ≥ 2⁻⁴¹ (smaller values
// lose only what lies below 2⁻⁶⁴ ≈ 5e-20), and integer addition is associative. The sum is rounded to a
// float once, when the bake finishes (docs/distributed.md).
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace irbake {

__extension__ using ExactInt = __int128;

// Per page, per texel that can receive light (a valid texel sample): Σ over the blocks added of the
// block's map value, and whether any block found the texel valid. A value is one RGB triple per
// coefficient: 1 coefficient (the map, L0) for a plain bake, 4 with directional maps (L0, then the L1x,
// L1y, L1z pages of transport/directional.h), so the L1 pages are as exact and as splittable as the map.
// Only those texels hold sums (48 bytes per coefficient; an index of 4 bytes per texel finds them).
struct ExactVplSums {
  static constexpr uint32_t kNoSum = UINT32_MAX;
  static constexpr int kMaxCoefficients = 4;  // L0 + L1x, L1y, L1z
  struct Page {
    std::vector<uint32_t> slot;   // per texel: index of its sums in values / (3 · coefficients), kNoSum: none
    std::vector<ExactInt> values; // 3 · coefficients per texel with a slot (coefficient-major, RGB each),
                                  // fixed point with kFractionBits fractional bits
    std::vector<uint8_t> valid;   // per texel: 1 where a block returned the texel valid
  };
  static constexpr int kFractionBits = 64;
  // Block values must stay below 2⁴⁰ (1.1e12): then 2²² blocks cannot overflow the 127 value bits.
  static constexpr double kMaxBlockValue = 1099511627776.0;  // 2⁴⁰
  int coefficients = 1;           // RGB triples per texel: 1 (L0) or 4 (L0 and the three L1 pages)
  std::vector<Page> pages;

  // Zero sums for pages whose texels ≠ 0 in `receivers` (one mask per page) can receive light, with
  // `coefficients` RGB triples per texel (1 … kMaxCoefficients; throws std::invalid_argument otherwise).
  static ExactVplSums zeros(const std::vector<std::vector<uint8_t>>& receivers, int coefficients = 1);
  // Adds one block's value at a texel: `coefficients` RGB triples from values[0]. False when a value is not
  // finite or too large to add exactly, or the texel was not a receiver; then nothing is added.
  bool add(size_t page, size_t texel, const glm::vec3* values);
  // The same for sums of one coefficient (throws std::invalid_argument for more).
  bool add(size_t page, size_t texel, const glm::vec3& value);
  // Adds another sum of the same layout (throws std::invalid_argument when the layouts differ).
  void add(const ExactVplSums& other);
  // The sum of one coefficient at a texel, rounded to float.
  glm::vec3 value(size_t page, size_t texel, int coefficient = 0) const;
  // Same coefficient count and, per page, the same receivers.
  bool sameLayout(const ExactVplSums& other) const;
  size_t channels() const { return 3 * static_cast<size_t>(coefficients); }
};

}  // namespace irbake
