// The GL backend's GPU resources (internal to baker/evaluators/gl): scene geometry, depth targets for
// punctual lights and VPL cubes, light-map pages, and one-name RAII owners. Each type deletes what it
// created when it goes, so a bake that throws half way leaks nothing.
#pragma once
#include <epoxy/gl.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "evaluators/gl/shadow_views.h"
#include "common/error.h"
#include "scene/scene.h"
#include "texels/texel_samples.h"

namespace irbake {

enum class GlObjectType { Buffer, Texture, VertexArray };

// One GL object name, deleted with its owner. Create through out(): glCreateBuffers(1, buffer.out()).
template <GlObjectType Type>
class GlObject {
 public:
  GlObject() = default;
  ~GlObject() { reset(); }
  GlObject(const GlObject&) = delete;
  GlObject& operator=(const GlObject&) = delete;
  GLuint get() const { return id_; }
  GLuint* out() {
    reset();
    return &id_;
  }
  void reset() {
    if (id_ == 0) return;
    switch (Type) {
      case GlObjectType::Buffer: glDeleteBuffers(1, &id_); break;
      case GlObjectType::Texture: glDeleteTextures(1, &id_); break;
      case GlObjectType::VertexArray: glDeleteVertexArrays(1, &id_); break;
    }
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};
using GlBuffer = GlObject<GlObjectType::Buffer>;
using GlTexture = GlObject<GlObjectType::Texture>;
using GlVertexArray = GlObject<GlObjectType::VertexArray>;

// One VPL as 3 RGBA32F texels of the buffer texture vplTable (shaders/vpl_accumulate.frag, loadVpl);
// the shader rebuilds the bitangent as normal × tangent, as vplFrame does.
struct VplTexels {
  glm::vec4 position;   // xyz VPL position, w Φ.r
  glm::vec4 normal;     // xyz unit normal (local +Z), w Φ.g
  glm::vec4 tangent;    // xyz local +X, w Φ.b
};

// Scene triangles on the GPU (world positions, one index buffer) with culling clusters.
struct GpuGeometry {
  GLuint vao = 0, vbo = 0, ibo = 0;
  std::vector<TriangleCluster> clusters;
  size_t triangles = 0;
  ~GpuGeometry() {
    glDeleteVertexArrays(1, &vao);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &ibo);
  }
};

// Punctual lights' depth targets: `layers` layers of size×size (a 2D array: 6 per cube) or one 2D map; one FBO
// per layer. (VPL cubes use the DepthAtlas below.)
struct DepthTargets {
  GLuint texture = 0;
  GLenum target = 0;
  int size = 0;
  std::vector<GLuint> fbos;
  DepthTargets(GLenum tgt, int sz, int layers) : target(tgt), size(sz) {
    glCreateTextures(target, 1, &texture);
    if (target == GL_TEXTURE_2D)
      glTextureStorage2D(texture, 1, GL_DEPTH_COMPONENT32F, size, size);
    else
      glTextureStorage3D(texture, 1, GL_DEPTH_COMPONENT32F, size, size, layers);
    glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(texture, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    fbos.resize(layers);
    glCreateFramebuffers(layers, fbos.data());
    for (int l = 0; l < layers; ++l) {
      if (target == GL_TEXTURE_2D)
        glNamedFramebufferTexture(fbos[l], GL_DEPTH_ATTACHMENT, texture, 0);
      else
        glNamedFramebufferTextureLayer(fbos[l], GL_DEPTH_ATTACHMENT, texture, 0, l);
      glNamedFramebufferDrawBuffer(fbos[l], GL_NONE);
      glNamedFramebufferReadBuffer(fbos[l], GL_NONE);
      if (glCheckNamedFramebufferStatus(fbos[l], GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw Error(ErrorCode::Gl, "", "depth framebuffer incomplete");
    }
  }
  ~DepthTargets() {
    glDeleteFramebuffers(static_cast<GLsizei>(fbos.size()), fbos.data());
    glDeleteTextures(1, &texture);
  }
};

// The VPL depth cubes of one batch as tiles of one 2D depth texture and framebuffer (one clear and one binned
// scene per batch, no framebuffer switch per face): tile 5k + f holds face f (GL order +X −X +Y −Y +Z; a
// hemisphere never needs −Z) of the batch's k-th VPL, at column (5k + f) % cols, row (5k + f) / cols.
struct DepthAtlas {
  static constexpr int kTilesPerCube = 5;
  GLuint texture = 0, fbo = 0;
  int faceSize = 0, cols = 1, rows = 1;
  DepthAtlas(int size, int cubes) : faceSize(size) {
    const int tiles = std::max(1, cubes * kTilesPerCube);
    GLint maxSize = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
    const int maxTiles = std::max(1, maxSize / size);
    // One cube per row (5 columns) when the rows fit: tile (face, cube), no division in the shader;
    // otherwise a near-square grid.
    cols = cubes <= maxTiles && kTilesPerCube <= maxTiles
               ? kTilesPerCube
               : std::min(maxTiles, std::max(1, int(std::ceil(std::sqrt(double(tiles))))));
    rows = (tiles + cols - 1) / cols;
    if (rows > maxTiles)
      throw Error(ErrorCode::Gl, "", "VPL depth atlas of " + std::to_string(tiles) + " tiles of " +
                                         std::to_string(size) + "² exceeds GL_MAX_TEXTURE_SIZE " +
                                         std::to_string(maxSize) + " (lower the VPLs per pass or the face size)");
    glCreateTextures(GL_TEXTURE_2D, 1, &texture);
    glTextureStorage2D(texture, 1, GL_DEPTH_COMPONENT32F, width(), height());
    glTextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(texture, GL_TEXTURE_COMPARE_MODE, GL_NONE);
    glTextureParameteri(texture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(texture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, texture, 0);
    glNamedFramebufferDrawBuffer(fbo, GL_NONE);
    glNamedFramebufferReadBuffer(fbo, GL_NONE);
    if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error(ErrorCode::Gl, "", "depth atlas framebuffer incomplete");
  }
  ~DepthAtlas() {
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &texture);
  }
  int width() const { return cols * faceSize; }
  int height() const { return rows * faceSize; }
  glm::ivec2 tileOrigin(int cube, int face) const {
    const int t = kTilesPerCube * cube + face;
    return glm::ivec2(t % cols, t / cols) * faceSize;
  }
};

// One page on the GPU: G-buffer (S×S layers), float accumulation target, double accumulator, and a validity
// mask as depth (1 valid, 0 not) that the early depth test uses to skip invalid texels before shading. With
// directional maps, three more float targets (attachments 1–3) and accumulators hold the L1 pages.
struct GpuPage {
  const TexelSamples* samples = nullptr;
  GLuint positionWeight = 0, normal = 0, geomNormal = 0, accum = 0, validDepth = 0, fbo = 0;
  GLuint l1Accum[3] = {0, 0, 0};  // directional only
  std::vector<glm::dvec3> sum;
  std::vector<double> leak;  // alpha: light of lookups that could not tell a contact from the receiver
  std::vector<glm::dvec3> l1Sum[3];  // directional only: the L1 pages' double accumulators
  std::vector<glm::vec4> readback;
  bool directional() const { return l1Accum[0] != 0; }
  GpuPage(const TexelSamples& s, const Scene& scene, bool validityMask, bool withL1)
      : samples(&s), sum(s.layerSize(), glm::dvec3(0.0)), leak(s.layerSize(), 0.0) {
    const int layers = s.supersample * s.supersample;
    if (s.positionWeight.size() != s.slotCount() || s.normal.size() != s.slotCount())
      throw Error(ErrorCode::InvalidData, "", "texel samples of page " + std::to_string(s.page) + " are incomplete");
    for (GLuint* t : {&positionWeight, &normal, &geomNormal}) {
      glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, t);
      glTextureStorage3D(*t, 1, GL_RGBA32F, s.width, s.height, layers);
      glTextureParameteri(*t, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(*t, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    }
    glTextureSubImage3D(positionWeight, 0, 0, 0, 0, s.width, s.height, layers, GL_RGBA, GL_FLOAT,
                        s.positionWeight.data());
    glTextureSubImage3D(normal, 0, 0, 0, 0, s.width, s.height, layers, GL_RGBA, GL_FLOAT, s.normal.data());
    // The sample's triangle's own normal: the depth bias follows the surface the shadow map sampled, not
    // the interpolated shading normal (smooth normals on a hard-edged box lean up to 55° off its faces).
    std::vector<glm::vec4> faceNormal(s.slotCount());
    for (size_t i = 0; i < faceNormal.size(); ++i) {
      faceNormal[i] = s.normal[i];
      if (i >= s.primitive.size() || i >= s.triangle.size() || s.primitive[i] >= scene.primitives.size()) continue;
      const Primitive& p = scene.primitives[s.primitive[i]];
      if (3 * size_t(s.triangle[i]) + 2 >= p.indices.size()) continue;
      const uint32_t* idx = &p.indices[3 * size_t(s.triangle[i])];
      const glm::vec3 n = glm::cross(p.positions[idx[1]] - p.positions[idx[0]], p.positions[idx[2]] - p.positions[idx[0]]);
      const float len = glm::length(n);
      // On the side the shading normal faces: a triangle wound against its normals is lit on the normals' side,
      // as the Embree backend and path tracers light it (the raw winding left such a surface black).
      const float side = glm::dot(n, glm::vec3(s.normal[i])) < 0.0f ? -1.0f : 1.0f;
      if (len > 0.0f && std::isfinite(len)) faceNormal[i] = glm::vec4(side * n / len, 0.0f);
    }
    glTextureSubImage3D(geomNormal, 0, 0, 0, 0, s.width, s.height, layers, GL_RGBA, GL_FLOAT, faceNormal.data());
    glCreateTextures(GL_TEXTURE_2D, 1, &accum);
    glTextureStorage2D(accum, 1, GL_RGBA32F, s.width, s.height);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, accum, 0);
    if (withL1) {
      glCreateTextures(GL_TEXTURE_2D, 3, l1Accum);
      for (int k = 0; k < 3; ++k) {
        glTextureStorage2D(l1Accum[k], 1, GL_RGBA32F, s.width, s.height);
        glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT1 + k, l1Accum[k], 0);
        l1Sum[k].assign(s.layerSize(), glm::dvec3(0.0));
      }
      const GLenum targets[4] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3};
      glNamedFramebufferDrawBuffers(fbo, 4, targets);
    }
    if (validityMask) {
      std::vector<float> depth(s.layerSize(), 1.0f);
      for (size_t i = 0; i < depth.size(); ++i) depth[i] = i < s.valid.size() && s.valid[i] ? 1.0f : 0.0f;
      glCreateTextures(GL_TEXTURE_2D, 1, &validDepth);
      glTextureStorage2D(validDepth, 1, GL_DEPTH_COMPONENT32F, s.width, s.height);
      glTextureSubImage2D(validDepth, 0, 0, 0, s.width, s.height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
      glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, validDepth, 0);
    }
    if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw Error(ErrorCode::Gl, "", "accumulation framebuffer incomplete");
    clear();
  }
  ~GpuPage() {
    glDeleteFramebuffers(1, &fbo);
    GLuint t[8] = {positionWeight, normal, geomNormal, accum, validDepth, l1Accum[0], l1Accum[1], l1Accum[2]};
    glDeleteTextures(8, t);  // names 0 are ignored
  }
  void clear() {
    const float zero[4] = {0, 0, 0, 0};
    glClearTexImage(accum, 0, GL_RGBA, GL_FLOAT, zero);
    if (directional())
      for (GLuint t : l1Accum) glClearTexImage(t, 0, GL_RGBA, GL_FLOAT, zero);
  }
  // Adds the float partial sums into the double accumulators and restarts them from zero.
  void fold() {
    readback.resize(samples->layerSize());
    auto read = [&](GLuint texture) {
      glGetTextureImage(texture, 0, GL_RGBA, GL_FLOAT, static_cast<GLsizei>(readback.size() * sizeof(glm::vec4)),
                        readback.data());
    };
    read(accum);
    for (size_t i = 0; i < sum.size(); ++i) {
      sum[i] += glm::dvec3(readback[i]);
      leak[i] += readback[i].w;
    }
    if (directional())
      for (int k = 0; k < 3; ++k) {
        read(l1Accum[k]);
        for (size_t i = 0; i < l1Sum[k].size(); ++i) l1Sum[k][i] += glm::dvec3(readback[i]);
      }
    clear();
  }
};

// See-through primitives (MASK holes, BLEND, transmission) are drawn into shadow maps of their own.
bool seeThrough(const Scene& scene, const Primitive& prim);

// The scene's opaque primitives (or, with seeThroughOnly, the see-through ones) as one vertex/index
// buffer in g, triangles in Morton order, with culling clusters of clusterTriangles.
void uploadGeometry(const Scene& scene, int clusterTriangles, GpuGeometry& g, bool seeThroughOnly = false);

}  // namespace irbake
