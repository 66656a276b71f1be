// The sky: light arriving from infinitely far away, as radiance per direction. Either uniform
// (`--sky R,G,B`) or an equirectangular image (`--env FILE.exr|.hdr`, +Y up, read with OpenImageIO).
//
// Equirectangular convention: pixel (u, v) ∈ [0,1]² (v = 0 the top row) is the direction with polar
// angle θ = π v from +Y and longitude φ = 2π u − π, d = (sinθ sinφ, cosθ, −sinθ cosφ): the image centre
// looks along −Z and u grows towards +X. `rotation` turns the environment about +Y (right-handed).
// Radiance is in W/(m² sr) (RGB, linear), like emission (docs/units.md).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace irbake {

class Environment {
 public:
  Environment() = default;
  // A sky of the same radiance in every direction.
  static Environment uniform(const glm::vec3& radiance);
  // An equirectangular map (width × height RGB, rows top to bottom), scaled by intensity, turned by
  // rotation (radians) about +Y.
  static Environment fromEquirect(int width, int height, std::vector<glm::vec3> texels, float intensity = 1.0f,
                                  float rotation = 0.0f, std::string source = {});

  bool present() const { return uniform_ != glm::vec3(0.0f) || !texels_.empty(); }
  bool isUniform() const { return texels_.empty(); }
  const glm::vec3& uniformRadiance() const { return uniform_; }
  const std::string& source() const { return source_; }
  int width() const { return width_; }
  int height() const { return height_; }
  float rotation() const { return rotation_; }
  // The map's texels (width × height, rows top to bottom, intensity applied); empty for a uniform sky.
  const std::vector<glm::vec3>& texels() const { return texels_; }

  // Radiance arriving from direction `towardSky` (unit, pointing away from the receiver).
  glm::vec3 radiance(const glm::vec3& towardSky) const;
  // A direction towards the sky, distributed ∝ luminance (uniform sphere for a uniform sky); pdf per sr.
  glm::vec3 sample(double u1, double u2, double& pdf) const;
  double pdf(const glm::vec3& towardSky) const;
  // ∫ L(ω) dω over the sphere (W/m², RGB): a sphere of radius R receives π R² · this (the walk's power).
  glm::dvec3 integral() const { return integral_; }

 private:
  glm::vec3 lookup(int x, int y) const { return texels_[static_cast<size_t>(y) * width_ + x]; }
  struct Texel {
    int x = 0, y = 0;
    double theta = 0.0;  // polar angle from +Y of the direction itself
  };
  Texel texelOf(const glm::vec3& towardSky) const;  // the map texel a direction reads
  glm::vec3 uniform_{0.0f};
  int width_ = 0, height_ = 0;
  std::vector<glm::vec3> texels_;
  float rotation_ = 0.0f;
  std::string source_;
  // Importance sampling: per row, the CDF over columns of luminance × sinθ; over rows, the marginal.
  std::vector<double> rowCdf_, columnCdf_;  // rowCdf_: height+1; columnCdf_: height × (width+1)
  double total_ = 0.0;                       // Σ luminance × sinθ over texels
  glm::dvec3 integral_{0.0};
};

// The largest radiance (W/(m² sr)) a sky or an environment pixel (× its intensity) may have: beyond it the sums
// of a bake leave single precision (the bound --sky has).
constexpr double kLargestSkyRadiance = 1e20;

// Reads an equirectangular EXR/HDR (any size; 1×1 is a uniform sky; one channel is grey) with OpenImageIO. Throws
// Error(Io/InvalidData) naming the file (missing, unreadable, negative or non-finite radiance, or a pixel that
// times intensity exceeds kLargestSkyRadiance) and Error(Usage) for an intensity outside [0, kLargestSkyRadiance].
Environment loadEnvironment(const std::filesystem::path& file, float intensity = 1.0f, float rotationDegrees = 0.0f);

}  // namespace irbake
