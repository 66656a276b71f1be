#include "pipeline/vpl_sums.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace irbake {

namespace {
ExactInt toFixed(float v) {
  // ldexp by a power of two is exact in double; the conversion truncates only bits below 2⁻⁶⁴.
  return static_cast<ExactInt>(std::ldexp(static_cast<double>(v), ExactVplSums::kFractionBits));
}
float fromFixed(ExactInt s) {
  return static_cast<float>(std::ldexp(static_cast<double>(s), -ExactVplSums::kFractionBits));
}
}  // namespace

ExactVplSums ExactVplSums::zeros(const std::vector<std::vector<uint8_t>>& receivers, int coefficients) {
  if (coefficients < 1 || coefficients > kMaxCoefficients)
    throw std::invalid_argument("VPL sums of " + std::to_string(coefficients) + " coefficients");
  ExactVplSums sums;
  sums.coefficients = coefficients;
  for (const std::vector<uint8_t>& mask : receivers) {
    Page p;
    p.slot.assign(mask.size(), kNoSum);
    uint32_t slots = 0;
    for (size_t t = 0; t < mask.size(); ++t)
      if (mask[t]) p.slot[t] = slots++;
    p.values.assign(sums.channels() * slots, 0);
    p.valid.assign(mask.size(), 0);
    sums.pages.push_back(std::move(p));
  }
  return sums;
}

bool ExactVplSums::add(size_t page, size_t texel, const glm::vec3* values) {
  const size_t n = channels();
  auto channel = [&](size_t c) { return values[c / 3][static_cast<int>(c % 3)]; };  // coefficient-major, RGB
  for (size_t c = 0; c < n; ++c)
    if (!std::isfinite(channel(c)) || std::fabs(channel(c)) >= kMaxBlockValue) return false;
  Page& p = pages[page];
  if (p.slot[texel] == kNoSum) return false;
  ExactInt* sum = &p.values[n * p.slot[texel]];
  for (size_t c = 0; c < n; ++c) sum[c] += toFixed(channel(c));
  p.valid[texel] = 1;
  return true;
}

bool ExactVplSums::add(size_t page, size_t texel, const glm::vec3& value) {
  if (coefficients != 1)
    throw std::invalid_argument("one RGB value added to VPL sums of " + std::to_string(coefficients) + " coefficients");
  return add(page, texel, &value);
}

void ExactVplSums::add(const ExactVplSums& other) {
  if (!sameLayout(other)) throw std::invalid_argument("VPL sums of different page layouts");
  for (size_t p = 0; p < pages.size(); ++p) {
    for (size_t i = 0; i < pages[p].values.size(); ++i) pages[p].values[i] += other.pages[p].values[i];
    for (size_t i = 0; i < pages[p].valid.size(); ++i) pages[p].valid[i] |= other.pages[p].valid[i];
  }
}

glm::vec3 ExactVplSums::value(size_t page, size_t texel, int coefficient) const {
  const Page& p = pages[page];
  if (p.slot[texel] == kNoSum) return glm::vec3(0.0f);
  const size_t s = channels() * p.slot[texel] + 3 * size_t(coefficient);
  return glm::vec3(fromFixed(p.values[s]), fromFixed(p.values[s + 1]), fromFixed(p.values[s + 2]));
}

bool ExactVplSums::sameLayout(const ExactVplSums& other) const {
  if (coefficients != other.coefficients || pages.size() != other.pages.size()) return false;
  for (size_t p = 0; p < pages.size(); ++p)
    if (pages[p].slot != other.pages[p].slot) return false;
  return true;
}

}  // namespace irbake
