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

ExactVplSums ExactVplSums::zeros(const std::vector<size_t>& texelsPerPage) {
  ExactVplSums sums;
  for (size_t n : texelsPerPage) {
    Page p;
    p.rgb.assign(3 * n, 0);
    p.valid.assign(n, 0);
    sums.pages.push_back(std::move(p));
  }
  return sums;
}

bool ExactVplSums::add(size_t page, size_t texel, const glm::vec3& value) {
  for (int c = 0; c < 3; ++c)
    if (!std::isfinite(value[c]) || std::fabs(value[c]) >= kMaxBlockValue) return false;
  Page& p = pages[page];
  for (int c = 0; c < 3; ++c) p.rgb[3 * texel + c] += toFixed(value[c]);
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
  return glm::vec3(fromFixed(p.rgb[3 * texel]), fromFixed(p.rgb[3 * texel + 1]), fromFixed(p.rgb[3 * texel + 2]));
}

bool ExactVplSums::sameLayout(const ExactVplSums& other) const {
  if (pages.size() != other.pages.size()) return false;
  for (size_t p = 0; p < pages.size(); ++p)
    if (pages[p].valid.size() != other.pages[p].valid.size() || pages[p].rgb.size() != other.pages[p].rgb.size())
      return false;
  return true;
}

}  // namespace irbake
