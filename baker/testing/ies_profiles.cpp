#include "testing/ies_profiles.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace irbake::testing {

namespace {

constexpr double kRad = 3.14159265358979323846 / 180.0;
const double kFactors[] = {1.5, 1.2, 0.5, 0.8, 1.5};  // at 0, 90, 180, 270, 360°

double horizontalFactor(double phi) {
  phi = std::fmod(phi, 360.0);
  if (phi < 0.0) phi += 360.0;
  const int k = std::min(3, static_cast<int>(phi / 90.0));
  const double t = (phi - 90.0 * k) / 90.0;
  return kFactors[k] * (1.0 - t) + kFactors[k + 1] * t;
}

}  // namespace

std::string iesProfileText(const std::vector<double>& vertical, const std::vector<double>& horizontal,
                           const std::function<double(double, double)>& candela, double multiplier) {
  std::ostringstream out;
  out.precision(17);
  out << "IESNA:LM-63-2002\n[TEST] irbake closed form\n[MANUFAC] irbake\nTILT=NONE\n";
  out << "1 -1 " << multiplier << " " << vertical.size() << " " << horizontal.size() << " 1 2 0 0 0\n1 1 0\n";
  auto list = [&](const std::vector<double>& values) {
    for (size_t i = 0; i < values.size(); ++i) out << values[i] << ((i + 1) % 10 == 0 || i + 1 == values.size() ? "\n" : " ");
  };
  list(vertical);
  list(horizontal);
  std::vector<double> values;
  for (double h : horizontal)
    for (double v : vertical) values.push_back(candela(v, h));
  list(values);
  return out.str();
}

std::string cosineIesProfile(double i0) {
  std::vector<double> vertical;
  for (int v = 0; v <= 90; ++v) vertical.push_back(v);
  return iesProfileText(vertical, {0, 90, 180, 270, 360},
                        [&](double theta, double phi) { return i0 * std::cos(theta * kRad) * horizontalFactor(phi); });
}

double cosineIesCandela(double i0, double theta, double phi) {
  if (theta > 90.0) return 0.0;
  const double lo = std::floor(theta), hi = std::min(90.0, lo + 1.0), t = theta - lo;
  const double c = (1.0 - t) * std::cos(lo * kRad) + t * std::cos(hi * kRad);
  return i0 * c * horizontalFactor(phi);
}

}  // namespace irbake::testing
