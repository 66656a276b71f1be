// IES LM-63 profiles written by the tests, from a closed-form candela distribution.
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace irbake::testing {

// LM-63-2002 text, TILT=NONE, photometric type C, candela(θ, φ) (degrees) at the given angles, ten values a line.
std::string iesProfileText(const std::vector<double>& vertical, const std::vector<double>& horizontal,
                           const std::function<double(double, double)>& candela, double multiplier = 1.0);

// The tests' closed form: I(θ, φ) = I0 · cosθ · f(φ) over the lower hemisphere (θ ≤ 90°, nothing above), θ
// every degree, f piecewise linear through f(0°) = 1.5, f(90°) = 1.2, f(180°) = 0.5, f(270°) = 0.8, f(360°) = 1.5.
std::string cosineIesProfile(double i0);
// cosineIesProfile's candela at (θ, φ) in degrees, with its bilinear interpolation's own cosine.
double cosineIesCandela(double i0, double theta, double phi);

}  // namespace irbake::testing
