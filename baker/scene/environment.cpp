#include "scene/environment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "common/error.h"
#include "common/maths.h"
#include "imageio/image_io.h"

namespace irbake {

namespace {

double luminance(const glm::vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

// Index of the interval of a CDF (size n+1, cdf[0] = 0, cdf[n] = 1) holding u, and u's place inside it.
size_t findInterval(const double* cdf, size_t n, double u, double& t) {
  size_t i = static_cast<size_t>(std::upper_bound(cdf, cdf + n + 1, u) - cdf);
  i = std::clamp<size_t>(i, 1, n) - 1;
  const double width = cdf[i + 1] - cdf[i];
  t = width > 0.0 ? std::clamp((u - cdf[i]) / width, 0.0, 1.0) : 0.5;
  return i;
}
}  // namespace

Environment Environment::uniform(const glm::vec3& radiance) {
  Environment e;
  e.uniform_ = radiance;
  e.integral_ = glm::dvec3(radiance) * (4.0 * kPi);
  return e;
}

Environment Environment::fromEquirect(int width, int height, std::vector<glm::vec3> texels, float intensity,
                                      float rotation, std::string source) {
  Environment e;
  e.width_ = width;
  e.height_ = height;
  e.texels_ = std::move(texels);
  for (glm::vec3& t : e.texels_) t *= intensity;
  e.rotation_ = rotation;
  e.source_ = std::move(source);
  e.rowCdf_.assign(height + 1, 0.0);
  e.columnCdf_.assign(static_cast<size_t>(height) * (width + 1), 0.0);
  const double texelSolidAngle = (2.0 * kPi / width) * (kPi / height);  // × sinθ
  for (int y = 0; y < height; ++y) {
    const double sinTheta = std::sin(kPi * (y + 0.5) / height);
    double* row = &e.columnCdf_[static_cast<size_t>(y) * (width + 1)];
    for (int x = 0; x < width; ++x) {
      const glm::vec3 L = e.lookup(x, y);
      row[x + 1] = row[x] + luminance(L) * sinTheta;
      e.integral_ += glm::dvec3(L) * (texelSolidAngle * sinTheta);
    }
    e.rowCdf_[y + 1] = e.rowCdf_[y] + row[width];
    if (row[width] > 0.0)
      for (int x = 1; x <= width; ++x) row[x] /= row[width];
  }
  e.total_ = e.rowCdf_[height];
  if (e.total_ > 0.0)
    for (double& c : e.rowCdf_) c /= e.total_;
  return e;
}

Environment::Texel Environment::texelOf(const glm::vec3& d) const {
  // Into the map's frame: undo the rotation about +Y.
  const float c = std::cos(rotation_), s = std::sin(rotation_);
  const glm::vec3 m(c * d.x - s * d.z, d.y, s * d.x + c * d.z);
  Texel t;
  t.theta = std::acos(std::clamp(static_cast<double>(m.y), -1.0, 1.0));
  const double phi = std::atan2(static_cast<double>(m.x), -static_cast<double>(m.z));
  t.x = std::clamp(static_cast<int>((phi + kPi) / (2.0 * kPi) * width_), 0, width_ - 1);
  t.y = std::clamp(static_cast<int>(t.theta / kPi * height_), 0, height_ - 1);
  return t;
}

glm::vec3 Environment::radiance(const glm::vec3& d) const {
  if (texels_.empty()) return uniform_;
  const Texel t = texelOf(d);
  return lookup(t.x, t.y);
}

glm::vec3 Environment::sample(double u1, double u2, double& pdf) const {
  if (texels_.empty() || total_ <= 0.0) {  // uniform sphere
    const double z = 1.0 - 2.0 * u1, r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = 2.0 * kPi * u2;
    pdf = 1.0 / (4.0 * kPi);
    return glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(z), static_cast<float>(r * std::sin(phi)));
  }
  double tv, tu;
  const size_t y = findInterval(rowCdf_.data(), height_, u1, tv);
  const size_t x = findInterval(&columnCdf_[y * (width_ + 1)], width_, u2, tu);
  const double v = (y + tv) / height_, u = (x + tu) / width_;
  const double theta = kPi * v, phi = 2.0 * kPi * u - kPi;
  const glm::dvec3 m(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
  const double c = std::cos(rotation_), s = std::sin(rotation_);
  const glm::vec3 d(static_cast<float>(c * m.x + s * m.z), static_cast<float>(m.y), static_cast<float>(-s * m.x + c * m.z));
  pdf = this->pdf(d);
  return d;
}

double Environment::pdf(const glm::vec3& d) const {
  if (texels_.empty() || total_ <= 0.0) return 1.0 / (4.0 * kPi);
  const Texel t = texelOf(d);
  const int x = t.x, y = t.y;
  const double theta = t.theta;
  // The texel's probability, uniform over its (u, v) rectangle; dω = 2π² sinθ du dv at the direction itself.
  const double sinCentre = std::sin(kPi * (y + 0.5) / height_), sinTheta = std::sin(theta);
  if (sinTheta <= 0.0) return 0.0;
  const double p = luminance(lookup(x, y)) * sinCentre / total_;
  return p * width_ * height_ / (2.0 * kPi * kPi * sinTheta);
}

Environment loadEnvironment(const std::filesystem::path& file, float intensity, float rotationDegrees) {
  const std::string name = file.string();
  if (!std::filesystem::exists(file)) throw Error(ErrorCode::Io, name, "environment image not found");
  if (!(intensity >= 0.0f) || !(intensity <= kLargestSkyRadiance))
    throw Error(ErrorCode::Usage, name, "--env-intensity must be a number in [0, 1e20]");
  // Read through the imageio plugin (OpenImageIO, loaded on first use: imageio/image_io.h).
  imageio::Pixels px;
  try {
    px = imageio::api().readFile(name);
  } catch (const Error& e) {
    throw Error(ErrorCode::InvalidData, name, std::string("cannot read the environment image (") + e.what() + ")");
  }
  if (px.width < 1 || px.height < 1 || px.channels < 1)
    throw Error(ErrorCode::InvalidData, name, "environment image has no pixels (" + std::to_string(px.width) + "×" +
                                                  std::to_string(px.height) + ", " + std::to_string(px.channels) + " channels)");
  std::vector<glm::vec3> texels(static_cast<size_t>(px.width) * px.height);
  for (size_t i = 0; i < texels.size(); ++i) {
    const float* p = &px.f32[i * px.channels];
    texels[i] = px.channels >= 3 ? glm::vec3(p[0], p[1], p[2]) : glm::vec3(p[0]);
    for (int c = 0; c < 3; ++c) {
      const std::string pixel = "environment pixel " + std::to_string(i % px.width) + "," + std::to_string(i / px.width);
      if (!std::isfinite(texels[i][c]) || texels[i][c] < 0.0f)
        throw Error(ErrorCode::InvalidData, name, pixel + " is negative or not finite");
      if (double(texels[i][c]) * intensity > kLargestSkyRadiance) {
        char amount[96];
        std::snprintf(amount, sizeof amount, "%g W/(m² sr) × --env-intensity %g", double(texels[i][c]), double(intensity));
        throw Error(ErrorCode::InvalidData, name,
                    pixel + " is " + amount + ", above the 1e20 W/(m² sr) whose sums a bake keeps finite in float");
      }
    }
  }
  // One pixel is a constant sky: exactly uniform (an equirect of one row would integrate sinθ at θ = π/2 only).
  if (texels.size() == 1) return Environment::uniform(texels[0] * intensity);
  return Environment::fromEquirect(px.width, px.height, std::move(texels), intensity,
                                   static_cast<float>(rotationDegrees * kPi / 180.0), name);
}

}  // namespace irbake
