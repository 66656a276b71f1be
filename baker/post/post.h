// Post-processing of baked pages: dilation of valid texels into padding and invalid texels, seam
// stitching between charts, and the finite check that keeps NaN/Inf out of every output.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

#include "lightmap/lightmap.h"
#include "scene/scene.h"

namespace irbake {

struct DilateOptions {
  int maxDistance = -1;  // rings of texels to grow (8-neighbourhood); -1 = until the page is full
};

// Fills every texel with valid == 0 from its filled 8-neighbours, ring by ring outwards from the
// valid texels (each new texel is the mean of the already-filled neighbours), so bilinear and mip
// lookups at a chart's border never read black. Valid texels are never changed; map.valid is kept.
// Returns the number of texels filled.
size_t dilate(Lightmap& map, const DilateOptions& options = {});

// One seam edge: the same 3D edge drawn twice in the atlas (two charts, or two pages). uvA/uvB are
// the edge's endpoints in the two charts, in the same 3D order.
struct SeamEdge {
  int pageA = 0, pageB = 0;
  glm::vec2 uvA0{0.0f}, uvA1{0.0f};
  glm::vec2 uvB0{0.0f}, uvB1{0.0f};
};

struct SeamOptions {
  float positionTolerance = 1e-5f;  // relative to the scene's bounding-box diagonal: "same 3D point"
  float normalCosTolerance = 0.999f; // vertex normals must agree this well (smooth surface) to stitch
  double seamWeight = 1.0;          // least-squares weight of "both sides agree" per seam sample
  double dataWeight = 0.001;        // least-squares weight of "texel keeps its baked value"
  int samplesPerTexel = 2;          // seam samples per texel of edge length (the longer side)
  int iterations = 64;              // conjugate-gradient iteration cap (Jacobi-preconditioned: a level's seams
                                    // settle well before it)
  double tolerance = 1e-8;          // stop when the residual is below this fraction of the right-hand side
};

// Finds the edges where a smooth surface is cut into different charts (equal positions and
// normals, different uv1 or page), over all lightmapped primitives.
std::vector<SeamEdge> findSeams(const Scene& scene, const SeamOptions& options = {});

// Least squares over the texels under the seams: minimise Σ w_s (bilinear_A − bilinear_B)² at
// sample points along every seam + w_d Σ (texel − baked)², solved per channel by conjugate
// gradients, so both sides of a seam show the same value. maps[i].page must equal i.
// Returns the RMS mismatch along the seams after stitching (0 when there are none).
double stitchSeams(std::vector<Lightmap>& maps, const std::vector<SeamEdge>& seams, const SeamOptions& options = {});

// RMS of (bilinear_A − bilinear_B) over the seam samples: how visible the seams are.
double seamMismatch(const std::vector<Lightmap>& maps, const std::vector<SeamEdge>& seams,
                    const SeamOptions& options = {});

// Bilinear lookup with texel centres at ((x+0.5)/W, (y+0.5)/H), row y = 0 at v = 0, clamped to the edge.
glm::vec3 sampleLightmap(const Lightmap& map, glm::vec2 uv);

// Throws Error(NumericError, what, "page P texel (x, y) is NaN/Inf") at the first non-finite texel.
void checkFinite(const Lightmap& map, const std::string& what);

struct PostOptions {
  bool dilate = true;        // fill invalid and padding texels from valid neighbours
  bool stitchSeams = true;   // make both sides of chart seams agree
  DilateOptions dilation;    // dilation settings
  SeamOptions seams;         // seam settings
};

struct PostStats {
  size_t texelsFilled = 0;       // texels written by dilation
  size_t seamEdges = 0;          // seam edges found
  double seamMismatchBefore = 0; // RMS seam mismatch before stitching
  double seamMismatchAfter = 0;  // and after
  nlohmann::json toJson() const {  // report "post"
    return {{"texelsFilled", texelsFilled}, {"seamEdges", seamEdges}, {"seamMismatchBefore", seamMismatchBefore},
            {"seamMismatchAfter", seamMismatchAfter}};
  }
};

// The whole post stage in order: finite check → dilation → seam stitching → finite check.
PostStats postProcess(const Scene& scene, std::vector<Lightmap>& maps, const PostOptions& options = {});

}  // namespace irbake
