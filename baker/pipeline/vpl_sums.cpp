#include "pipeline/vpl_sums.h"

#include <cmath>
#include <stdexcept>

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

ExactVplSums ExactVplSums::zeros(const std::vector<std::vector<uint8_t>>& receivers) {
  ExactVplSums sums;
  for (const std::vector<uint8_t>& mask : receivers) {
    Page p;
    p.slot.assign(mask.size(), kNoSum);
    uint32_t slots = 0;
    for (size_t t = 0; t < mask.size(); ++t)
      if (mask[t]) p.slot[t] = slots++;
    p.rgb.assign(3 * size_t(slots), 0);
    p.valid.assign(mask.size(), 0);
    sums.pages.push_back(std::move(p));
  }
  return sums;
}

bool ExactVplSums::add(size_t page, size_t texel, const glm::vec3& value) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(value[c]) || std::fabs(value[c]) >= kMaxBlockValue) return false;
  Page& p = pages[page];
  if (p.slot[texel] == kNoSum) return false;
  for (int c = 0; c < 3; ++c) p.rgb[3 * size_t(p.slot[texel]) + c] += toFixed(value[c]);
  p.valid[texel] = 1;
  return true;
}

void ExactVplSums::add(const ExactVplSums& other) {
  if (!sameLayout(other)) throw std::invalid_argument("VPL sums of different page layouts");
  for (size_t p = 0; p < pages.size(); ++p) {
    for (size_t i = 0; i < pages[p].rgb.size(); ++i) pages[p].rgb[i] += other.pages[p].rgb[i];
    for (size_t i = 0; i < pages[p].valid.size(); ++i) pages[p].valid[i] |= other.pages[p].valid[i];
  }
}

glm::vec3 ExactVplSums::value(size_t page, size_t texel) const {
  const Page& p = pages[page];
  if (p.slot[texel] == kNoSum) return glm::vec3(0.0f);
  const size_t s = 3 * size_t(p.slot[texel]);
  return glm::vec3(fromFixed(p.rgb[s]), fromFixed(p.rgb[s + 1]), fromFixed(p.rgb[s + 2]));
}

bool ExactVplSums::sameLayout(const ExactVplSums& other) const {
  if (pages.size() != other.pages.size()) return false;
  for (size_t p = 0; p < pages.size(); ++p)
    if (pages[p].slot != other.pages[p].slot) return false;
  return true;
}

}  // namespace irbake
