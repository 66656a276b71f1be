#include "evaluators/gl/gl_backend.h"

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include <time.h>

#include "evaluators/gl/gl_resources.h"
#include "evaluators/gl/gpu_timer.h"
#include "common/checksum.h"
#include "bake_interface.glsl"  // texture units and light codes, shared with the shaders
#include "evaluators/gl/shadow_views.h"
#include "common/error.h"
#include "common/log.h"
#include "common/progress.h"
#include "glcontext/gl_context.h"
#include "glcontext/gl_program.h"
#include "lights/light_kind.h"

namespace irbake {

namespace {

constexpr int kFaces = 6;

// The direct-light shader's shadow-map codes (shaders/bake_interface.glsl); its light codes are the light kinds'.
enum class ShadowKind : int {
  Cube = BAKE_SHADOW_CUBE,                  // six faces (points, wide spots)
  Perspective = BAKE_SHADOW_PERSPECTIVE,    // one perspective map (spots), reversed-Z
  Orthographic = BAKE_SHADOW_ORTHOGRAPHIC,  // one orthographic box (directional)
};

// Process CPU time (every thread, so llvmpipe's rasteriser threads count): comparable across machine load.
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

// Wall and CPU stopwatch for one stage.
struct StageClock {
  Stopwatch wall;
  double cpuStart = processCpuSeconds();
  void reset() {
    wall.reset();
    cpuStart = processCpuSeconds();
  }
};

class GlBaker {
 public:
  GlBaker(const BakeInputs& in, const GlBackendOptions& opt, const EvaluationRequest& request, GlBakeStats& stats,
          const GlContext& context)
      : in_(in), opt_(opt), request_(request), stats_(stats), context_(context), programs_(context.programs()),
        gpuTimer_(opt.gpuTimers) {}

  // The maps, and with EvaluationRequest::directional their L1 pages.
  std::vector<Lightmap> run();
  std::vector<Lightmap> readMaps();
  // Per page, per texel: 1 where the shadow lookups could not tell a contact from the receiver (after run).
  const std::vector<std::vector<uint8_t>>& contactTexels() const { return contactTexels_; }

 private:
  void drawView(const ShadowView& view, GLuint fbo, int size, bool reversedZ);
  void drawCulled(const ShadowView& view, int size);
  void renderVplBatch(size_t first, size_t count, const DepthAtlas& atlas);
  void renderVplCubes(size_t first, size_t count, const DepthAtlas& atlas, const GpuGeometry& geometry);
  void accumulateVplBatch(size_t first, size_t count, const DepthAtlas& atlas);
  void bakeDirect(const Light& light);
  // Whether light i's reach meets the scene's bounds (lights/light_reach.h): a light that misses it renders nothing.
  bool reachesScene(size_t i) {
    if (!in_.lightGrid || !in_.lightGrid->culls()) return true;
    if (!sceneBounds_) sceneBounds_ = in_.scene.bounds();
    return in_.lightGrid->touches(i, sceneBounds_->min, sceneBounds_->max);
  }
  void bindGBuffer(const GpuPage& page) const;
  void shadowPassState() const;
  void lightMapPassState() const;
  const GlProgram& vplProgram(int layers);
  // The contact check runs on the default lookup (2×2 filter); with the other lookups alpha stays 0.
  bool contactFlags() const { return opt_.resolveContacts && opt_.shadowPcf && opt_.shadowCompare; }
  bool directional() const { return request_.directional != nullptr; }
  bool wanted(size_t page, size_t texel) const {
    const auto* subset = request_.texelSubset;
    return !subset || (page < subset->size() && texel < (*subset)[page].size() && (*subset)[page][texel] != 0);
  }
  void finishStage(double& seconds, StageClock& sw, double* cpuSeconds = nullptr) const;
  std::shared_ptr<GpuGeometry> sharedGeometry(bool seeThroughOnly);

  const BakeInputs& in_;
  const GlBackendOptions& opt_;
  const EvaluationRequest& request_;
  GlBakeStats& stats_;
  const GlContext& context_;
  GlProgramCache& programs_;  // the context's: programs outlive this call, so later calls skip compiling
  ShadowScale scale_;
  std::shared_ptr<GpuGeometry> geometry_;            // opaque primitives (the context's, see sharedGeometry)
  std::shared_ptr<GpuGeometry> seeThroughGeometry_;  // MASK / BLEND / transmissive primitives (null: none)
  GpuTimer gpuTimer_;
  const GpuGeometry* drawing_ = nullptr;             // what drawCulled draws
  std::vector<std::unique_ptr<GpuPage>> pages_;
  const GlProgram* depthProgram_ = nullptr;
  GLint shadowViewLocation_ = -1;  // depthProgram_'s shadowView[5]
  const GlProgram* directProgram_ = nullptr;
  GlBuffer vplBuffer_;       // the VPL batch (VplTexels)
  GlTexture vplTable_;       // vplBuffer_ seen as an RGBA32F buffer texture
  GlVertexArray emptyVao_;   // full-screen passes draw without attributes
  std::vector<GLsizei> drawCounts_;
  std::vector<const void*> drawOffsets_;
  std::vector<std::vector<uint8_t>> contactTexels_;
  std::unique_ptr<DepthAtlas> seeThroughAtlas_;  // the same cubes of the see-through primitives alone
  std::optional<Bounds3> sceneBounds_;  // what reachesScene tests, once
  std::unique_ptr<DepthAtlas> atlas_;  // VPL depth cubes of one batch (created before the programs: its layout is compiled in)
};

void GlBaker::finishStage(double& seconds, StageClock& sw, double* cpuSeconds) const {
  if (opt_.stageTimings) glFinish();
  seconds += sw.wall.seconds();
  if (cpuSeconds) *cpuSeconds += processCpuSeconds() - sw.cpuStart;
  sw.reset();
}

// The scene's geometry on this context: uploaded by a bake's first call and reused by the next ones
// (interleaved sampling calls the backend n² + 1 times). Keyed by the scene's address and a checksum of its
// positions and indices, so another scene at the same address uploads its own.
std::shared_ptr<GpuGeometry> GlBaker::sharedGeometry(bool seeThroughOnly) {
  Checksum64 sum;
  for (const Primitive& p : in_.scene.primitives) {
    sum.add(p.positions.data(), p.positions.size() * sizeof(glm::vec3));
    sum.add(p.indices.data(), p.indices.size() * sizeof(uint32_t));
  }
  char key[96];
  std::snprintf(key, sizeof key, "gl.geometry.%p.%s.%d.%s", static_cast<const void*>(&in_.scene), sum.hex().c_str(),
                opt_.clusterTriangles, seeThroughOnly ? "see-through" : "opaque");
  std::shared_ptr<void>& slot = context_.resource(key);
  if (!slot) {
    Stopwatch watch;
    auto g = std::make_shared<GpuGeometry>();
    uploadGeometry(in_.scene, std::max(1, opt_.clusterTriangles), *g, seeThroughOnly);
    slot = g;
    stats_.geometrySeconds += watch.seconds();
  }
  return std::static_pointer_cast<GpuGeometry>(slot);
}

// Depth-only views: depth test and writes, no blending (punctual maps scissor in drawView; VPL faces clip).
void GlBaker::shadowPassState() const {
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
}

// Light-map passes: additive blending; with the validity mask, depth 0 passes GL_LESS only where the
// mask holds 1 (valid texels), and the mask is never written.
void GlBaker::lightMapPassState() const {
  glDisable(GL_SCISSOR_TEST);
  glEnable(GL_BLEND);
  if (opt_.skipInvalidTexels) {
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LESS);
  } else {
    glDisable(GL_DEPTH_TEST);
  }
}

void GlBaker::drawView(const ShadowView& view, GLuint fbo, int size, bool reversedZ) {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, size, size);
  glEnable(GL_SCISSOR_TEST);
  glScissor(view.scissor.x, view.scissor.y, view.scissor.z, view.scissor.w);
  glClearDepthf(reversedZ ? 0.0f : 1.0f);
  glDepthFunc(reversedZ ? GL_GREATER : GL_LESS);
  glClear(GL_DEPTH_BUFFER_BIT);
  drawCulled(view, size);
}

// The view's clusters that survive CPU culling, into the bound framebuffer's viewport; the view's scissor
// rectangle (of a size² view) goes to the shader as clip distances (active where GL_CLIP_DISTANCE0..3 are
// enabled: the VPL batches).
void GlBaker::drawCulled(const ShadowView& view, int size) {
  const float toNdc = 2.0f / static_cast<float>(size);
  glm::vec4 data[5] = {view.clip[0], view.clip[1], view.clip[2], view.clip[3],
                       glm::vec4(view.scissor.x * toNdc - 1.0f, (view.scissor.x + view.scissor.z) * toNdc - 1.0f,
                                 view.scissor.y * toNdc - 1.0f, (view.scissor.y + view.scissor.w) * toNdc - 1.0f)};
  glUniform4fv(shadowViewLocation_, 5, &data[0][0]);
  drawCounts_.clear();
  drawOffsets_.clear();
  cullClusters(view, drawing_->clusters, drawCounts_, drawOffsets_, stats_.trianglesDrawn);
  stats_.trianglesBeforeCulling += drawing_->triangles;
  ++stats_.facesRendered;
  if (!drawCounts_.empty())
    glMultiDrawElements(GL_TRIANGLES, drawCounts_.data(), GL_UNSIGNED_INT, drawOffsets_.data(),
                        static_cast<GLsizei>(drawCounts_.size()));
}

// The batch's cubes into the atlas: one clear (reversed-Z: 0 = nothing drawn), then each face in its tile's
// viewport, kept inside it by clip distances (shaders/shadow_depth.vert): cheaper than a scissor per face on
// llvmpipe. A glFlush every shadowFlushTriangles lets the rasteriser threads work while later faces are binned.
void GlBaker::renderVplBatch(size_t first, size_t count, const DepthAtlas& atlas) {
  drawing_ = geometry_.get();
  renderVplCubes(first, count, atlas, *geometry_);
  if (seeThroughAtlas_) {  // the see-through primitives' own cubes (contact texels)
    drawing_ = seeThroughGeometry_.get();
    renderVplCubes(first, count, *seeThroughAtlas_, *seeThroughGeometry_);
    drawing_ = geometry_.get();
  }
}

void GlBaker::renderVplCubes(size_t first, size_t count, const DepthAtlas& atlas, const GpuGeometry& geometry) {
  depthProgram_->use();
  glBindVertexArray(geometry.vao);
  glBindFramebuffer(GL_FRAMEBUFFER, atlas.fbo);
  glDisable(GL_SCISSOR_TEST);  // the clear covers the whole atlas
  glClearDepthf(0.0f);
  glClear(GL_DEPTH_BUFFER_BIT);
  for (int d = 0; d < 4; ++d) glEnable(GL_CLIP_DISTANCE0 + d);
  glDepthFunc(GL_GREATER);
  const int size = atlas.faceSize;
  const size_t flushTriangles = static_cast<size_t>(std::max(0, opt_.shadowFlushTriangles));
  size_t trianglesSinceFlush = 0;
  for (size_t k = 0; k < count; ++k) {
    const Vpl& v = in_.vpls.vpls[first + k];
    const VplFrame frame = vplFrame(v.normal);
    const glm::vec3 origin = v.position + frame.normal * scale_.originOffset;
    for (int face = 0; face < DepthAtlas::kTilesPerCube; ++face) {
      std::optional<ShadowView> view = cubeFaceView(origin, frame, face, size, scale_.nearPlane, true);
      if (!view) continue;
      const glm::ivec2 o = atlas.tileOrigin(static_cast<int>(k), face);
      glViewport(o.x, o.y, size, size);
      const size_t before = stats_.trianglesDrawn;
      drawCulled(*view, size);
      trianglesSinceFlush += stats_.trianglesDrawn - before;
      if (flushTriangles > 0 && trianglesSinceFlush >= flushTriangles) {
        glFlush();
        trianglesSinceFlush = 0;
      }
    }
  }
  for (int d = 0; d < 4; ++d) glDisable(GL_CLIP_DISTANCE0 + d);
}

void GlBaker::bindGBuffer(const GpuPage& page) const {
  glBindTextureUnit(BAKE_UNIT_POSITION_WEIGHT, page.positionWeight);
  glBindTextureUnit(BAKE_UNIT_NORMAL, page.normal);
  glBindTextureUnit(BAKE_UNIT_GEOMETRIC_NORMAL, page.geomNormal);
}

void GlBaker::accumulateVplBatch(size_t first, size_t count, const DepthAtlas& atlas) {
  std::vector<VplTexels> batch(count);
  for (size_t k = 0; k < count; ++k) {
    const Vpl& v = in_.vpls.vpls[first + k];
    const VplFrame f = vplFrame(v.normal);
    batch[k] = {glm::vec4(v.position, v.power.r), glm::vec4(f.normal, v.power.g), glm::vec4(f.tangent, v.power.b)};
  }
  if (count > 0) glNamedBufferSubData(vplBuffer_.get(), 0, batch.size() * sizeof(VplTexels), batch.data());
  glBindTextureUnit(BAKE_UNIT_VPL_TABLE, vplTable_.get());
  glBindTextureUnit(BAKE_UNIT_VPL_DEPTH, atlas.texture);
  if (seeThroughAtlas_) glBindTextureUnit(BAKE_UNIT_VPL_SEE_THROUGH_DEPTH, seeThroughAtlas_->texture);
  glBindVertexArray(emptyVao_.get());
  for (auto& page : pages_) {
    const GlProgram& program = vplProgram(page->samples->supersample * page->samples->supersample);
    program.use();
    glUniform1i(program.uniform("vplCount"), static_cast<GLint>(count));
    glBindFramebuffer(GL_FRAMEBUFFER, page->fbo);
    glViewport(0, 0, page->samples->width, page->samples->height);
    bindGBuffer(*page);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
}

// The accumulation program for pages of `layers` supersample layers (compiled on first use).
const GlProgram& GlBaker::vplProgram(int layers) {
  std::vector<std::string> defines{"#define LAYERS " + std::to_string(layers)};
  if (opt_.shadowPcf) defines.push_back(opt_.shadowCompare ? "#define SHADOW_COMPARE 1" : "#define SHADOW_PCF 1");
  if (contactFlags()) defines.push_back("#define CONTACT_FLAGS 1");
  if (seeThroughGeometry_) defines.push_back("#define SEE_THROUGH 1");
  if (directional()) defines.push_back("#define DIRECTIONAL 1");
  auto constant = [&](const char* name, float value) {
    char text[64];
    std::snprintf(text, sizeof text, "#define %s %.9e", name, double(value));  // round-trips the float
    defines.push_back(text);
  };
  constant("CLAMP_BOUND", std::isfinite(in_.eval.clampBound) ? in_.eval.clampBound : 0.0f);  // ≤ 0: no clamp
  constant("NEAR_PLANE", scale_.nearPlane);
  constant("CONSTANT_BIAS", scale_.constantBias);
  constant("SLOPE_BIAS", opt_.slopeBias);
  constant("NORMAL_OFFSET", opt_.normalOffset);
  constant("TEXEL_ANGLE", 2.0f / (atlas_ ? atlas_->faceSize : 256));
  constant("ORIGIN_OFFSET", scale_.originOffset);
  if (atlas_) {  // the depth atlas layout (tiles of FACE_SIZE², ATLAS_COLS per row)
    constant("FACE_SIZE", float(atlas_->faceSize));
    constant("ATLAS_INV_WIDTH", 1.0f / atlas_->width());
    constant("ATLAS_INV_HEIGHT", 1.0f / atlas_->height());
    defines.push_back("#define ATLAS_COLS " + std::to_string(atlas_->cols));
  }
  if (opt_.normalOffset != 0.0f) defines.push_back("#define HAS_NORMAL_OFFSET 1");
  return programs_.get(std::vector<ShaderStage>{{GL_VERTEX_SHADER, {"lightmap_pass.vert"}},
                                                {GL_FRAGMENT_SHADER, {"bake_interface.glsl", "ir_transport.glsl", "vpl_accumulate.frag"}}},
                      defines);
}

namespace {

// An IES profile's table (IesProfile::table) for direct_light.frag, θ every quarter degree, φ every degree: a
// profile measured at such angles reads back exactly.
constexpr int kIesTableRows = 721, kIesTableColumns = 361;

void uploadIesProfile(const IesProfile& profile, GlTexture& texture) {
  const std::vector<float> table = profile.table(kIesTableRows, kIesTableColumns);
  glCreateTextures(GL_TEXTURE_2D, 1, texture.out());
  glTextureStorage2D(texture.get(), 1, GL_R32F, kIesTableColumns, kIesTableRows);
  glTextureSubImage2D(texture.get(), 0, 0, 0, kIesTableColumns, kIesTableRows, GL_RED, GL_FLOAT, table.data());
  glBindTextureUnit(BAKE_UNIT_IES_PROFILE, texture.get());
}

}  // namespace

void GlBaker::bakeDirect(const Light& light) {
  const Bounds3 bounds = in_.scene.bounds();
  StageClock sw;
  // Shadow map as the light's kind asks: full cube for points and wide spots, perspective map for spots, ortho box
  // for directional.
  const LightKind& kind = lightKind(light.type);
  const ShadowProjection projection = kind.shadowProjection(light, opt_.maxSpotPerspectiveAngle);
  const bool cube = projection == ShadowProjection::Cube;
  std::unique_ptr<DepthTargets> maps;
  std::optional<ShadowView> view2d;
  float texelAngle = 0.0f, orthoRange = 0.0f;
  ShadowKind shadowKind = ShadowKind::Cube;
  depthProgram_->use();
  glBindVertexArray(geometry_->vao);
  shadowPassState();
  gpuTimer_.begin(&stats_.gpuShadowSeconds);
  if (cube) {
    maps = std::make_unique<DepthTargets>(GL_TEXTURE_2D_ARRAY, opt_.pointFaceSize, kFaces);
    const VplFrame identity{glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)};
    for (int face = 0; face < kFaces; ++face)
      drawView(*cubeFaceView(light.position, identity, face, maps->size, scale_.nearPlane, false), maps->fbos[face],
               maps->size, true);
    texelAngle = 2.0f / maps->size;
  } else if (projection == ShadowProjection::Perspective) {
    maps = std::make_unique<DepthTargets>(GL_TEXTURE_2D, opt_.lightMapSize, 1);
    float tanHalf = 0.0f;
    view2d = spotView(light.position, light.direction, light.outerConeAngle, opt_.lightMapSize, scale_.nearPlane,
                      tanHalf);
    drawView(*view2d, maps->fbos[0], maps->size, true);
    texelAngle = 2.0f * tanHalf / maps->size;
    shadowKind = ShadowKind::Perspective;
  } else {
    maps = std::make_unique<DepthTargets>(GL_TEXTURE_2D, opt_.lightMapSize, 1);
    float texelSize = 0.0f;
    view2d = directionalView(light.direction, bounds, opt_.lightMapSize, texelSize, orthoRange);
    drawView(*view2d, maps->fbos[0], maps->size, false);
    texelAngle = texelSize;
    shadowKind = ShadowKind::Orthographic;
  }
  // The see-through primitives into maps of their own, with the same views (contact texels).
  std::unique_ptr<DepthTargets> glassMaps;
  if (seeThroughGeometry_) {
    drawing_ = seeThroughGeometry_.get();
    glBindVertexArray(seeThroughGeometry_->vao);
    glassMaps = std::make_unique<DepthTargets>(maps->target, maps->size, static_cast<int>(maps->fbos.size()));
    if (cube) {
      const VplFrame identity{glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)};
      for (int face = 0; face < kFaces; ++face)
        drawView(*cubeFaceView(light.position, identity, face, glassMaps->size, scale_.nearPlane, false),
                 glassMaps->fbos[face], glassMaps->size, true);
    } else {
      drawView(*view2d, glassMaps->fbos[0], glassMaps->size, shadowKind == ShadowKind::Perspective);
    }
    drawing_ = geometry_.get();
  }
  finishStage(stats_.shadowSeconds, sw, &stats_.shadowCpuSeconds);

  gpuTimer_.begin(&stats_.gpuAccumulateSeconds);
  lightMapPassState();  // blended: added to the VPL partial sums not yet folded
  directProgram_->use();
  const GlProgram& p = *directProgram_;
  const ShaderLight shaderLight = kind.shaderLight(light);
  glUniform1i(p.uniform("lightType"), shaderLight.code);
  glUniform1i(p.uniform("shadowKind"), static_cast<int>(shadowKind));
  glUniform3fv(p.uniform("lightPosition"), 1, &light.position[0]);
  glUniform3fv(p.uniform("lightDirection"), 1, &light.direction[0]);
  glUniform3fv(p.uniform("lightAxisX"), 1, &light.profileAxisX[0]);
  GlTexture profileTexture;
  if (shaderLight.code == BAKE_LIGHT_IES && light.profile) uploadIesProfile(*light.profile, profileTexture);
  glUniform3fv(p.uniform("lightIntensity"), 1, &shaderLight.intensity[0]);
  glUniform1f(p.uniform("lightRange"), light.range);
  glUniform1f(p.uniform("lightCutoff"), light.cutoff);
  glUniform1f(p.uniform("cosOuter"), shaderLight.cosOuter);
  glUniform1f(p.uniform("spotScale"), shaderLight.spotScale);
  const glm::mat4 clip = view2d ? view2d->clip : glm::mat4(1.0f);
  glUniformMatrix4fv(p.uniform("shadowClip"), 1, GL_FALSE, &clip[0][0]);
  const glm::mat4 clipInverse = glm::inverse(clip);
  glUniformMatrix4fv(p.uniform("shadowClipInverse"), 1, GL_FALSE, &clipInverse[0][0]);
  glUniform1i(p.uniform("contactFlags"), opt_.resolveContacts ? 1 : 0);
  glUniform1f(p.uniform("orthoDepthRange"), orthoRange);
  glUniform1f(p.uniform("texelAngle"), texelAngle);
  glBindTextureUnit(cube ? BAKE_UNIT_LIGHT_CUBE : BAKE_UNIT_LIGHT_MAP, maps->texture);
  glUniform1i(p.uniform("seeThroughMaps"), glassMaps ? 1 : 0);
  if (glassMaps) glBindTextureUnit(cube ? BAKE_UNIT_GLASS_CUBE : BAKE_UNIT_GLASS_MAP, glassMaps->texture);
  glBindVertexArray(emptyVao_.get());
  for (auto& page : pages_) {
    glBindFramebuffer(GL_FRAMEBUFFER, page->fbo);
    glViewport(0, 0, page->samples->width, page->samples->height);
    bindGBuffer(*page);
    glUniform1i(p.uniform("layers"), page->samples->supersample * page->samples->supersample);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  gpuTimer_.end();
  finishStage(stats_.accumulateSeconds, sw, &stats_.accumulateCpuSeconds);
}

// The pages' double sums as maps (valid texels of the subset only), and the contact texels: those where
// lookups that could not tell a contact from the receiver carried more than contactLeakFraction of the light.
std::vector<Lightmap> GlBaker::readMaps() {
  std::vector<Lightmap> maps;
  if (directional())
    for (auto& axis : *request_.directional) axis.clear();
  for (size_t p = 0; p < pages_.size(); ++p) {
    const auto& page = pages_[p];
    const TexelSamples& s = *page->samples;
    Lightmap m;
    m.page = s.page;
    m.width = s.width;
    m.height = s.height;
    m.texels.resize(m.size());
    m.valid.assign(m.size(), 0);
    std::vector<uint8_t>& contact = contactTexels_.emplace_back(m.size(), 0);
    for (size_t i = 0; i < m.size(); ++i) {
      const bool valid = i < s.valid.size() && s.valid[i] && wanted(p, i);
      m.valid[i] = valid ? 1 : 0;
      stats_.texelsEvaluated += valid;
      if (valid && page->leak[i] > 0.0 &&
          page->leak[i] > opt_.contactLeakFraction * (page->sum[i].x + page->sum[i].y + page->sum[i].z) / 3.0)
        contact[i] = 1;
      const glm::dvec3 v = valid ? page->sum[i] : glm::dvec3(0.0);
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
        throw Error(ErrorCode::NumericError, "", "GL backend produced a non-finite texel on page " +
                                                     std::to_string(s.page));
      m.texels[i] = glm::vec3(v);
    }
    if (directional())
      for (int k = 0; k < 3; ++k) {
        Lightmap axis = m;
        for (size_t i = 0; i < axis.size(); ++i) {
          const glm::dvec3 v = axis.valid[i] ? page->l1Sum[k][i] : glm::dvec3(0.0);
          if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z))
            throw Error(ErrorCode::NumericError, "", "GL backend produced a non-finite directional texel on page " +
                                                         std::to_string(s.page));
          axis.texels[i] = glm::vec3(v);
        }
        (*request_.directional)[k].push_back(std::move(axis));
      }
    maps.push_back(std::move(m));
  }
  return maps;
}

std::vector<Lightmap> GlBaker::run() {
  StageClock sw;
  const float diagonal = std::max(in_.scene.bounds().diagonal(), 1e-6f);
  scale_.nearPlane = opt_.nearPlaneScale * diagonal;
  scale_.constantBias = opt_.constantBiasScale * diagonal;
  scale_.originOffset = std::max(in_.rayTracer.epsilon(), scale_.constantBias);

  geometry_ = sharedGeometry(false);
  drawing_ = geometry_.get();
  if (contactFlags() && std::any_of(in_.scene.primitives.begin(), in_.scene.primitives.end(),
                                    [&](const Primitive& p) { return seeThrough(in_.scene, p); }))
    seeThroughGeometry_ = sharedGeometry(true);
  for (const TexelSamples& s : in_.texels)
    pages_.push_back(std::make_unique<GpuPage>(s, in_.scene, opt_.skipInvalidTexels, directional()));

  const int vplsPerPass = std::clamp(opt_.vplsPerPass, 1, 256);
  depthProgram_ = &programs_.get(
      std::vector<ShaderStage>{{GL_VERTEX_SHADER, {"shadow_depth.vert"}}, {GL_FRAGMENT_SHADER, {"shadow_depth.frag"}}});
  shadowViewLocation_ = depthProgram_->uniform("shadowView");
  directProgram_ = &programs_.get(std::vector<ShaderStage>{{GL_VERTEX_SHADER, {"lightmap_pass.vert"}},
                                                           {GL_FRAGMENT_SHADER, {"bake_interface.glsl", "ir_transport.glsl", "light_range.glsl", "direct_light.frag"}}},
                                  directional() ? std::vector<std::string>{"#define DIRECTIONAL 1"} : std::vector<std::string>{});
  {
    const GlProgram* p = directProgram_;
    p->use();
    glUniform1f(p->uniform("clampBound"), in_.eval.clampBound);
    glUniform1f(p->uniform("nearPlane"), scale_.nearPlane);
    glUniform1f(p->uniform("constantBias"), scale_.constantBias);
    glUniform1f(p->uniform("slopeBias"), opt_.slopeBias);
    glUniform1f(p->uniform("normalOffset"), opt_.normalOffset);
  }
  if (in_.eval.includeVpls && !in_.vpls.vpls.empty()) {
    const int faceSize = opt_.cubeFaceSize
                             ? *opt_.cubeFaceSize
                             : chooseCubeFaceSize(in_.vpls.vpls, in_.texels, in_.eval.clampBound, opt_.cubeFootprintPerTexel,
                                                  opt_.minCubeFaceSize,
                                                  opt_.maxCubeFaceSize)
                                   .size;
    stats_.cubeFaceSize = faceSize;
    atlas_ = std::make_unique<DepthAtlas>(faceSize, vplsPerPass);
    if (seeThroughGeometry_) seeThroughAtlas_ = std::make_unique<DepthAtlas>(faceSize, vplsPerPass);
    for (const auto& page : pages_) vplProgram(page->samples->supersample * page->samples->supersample);
  }
  glCreateBuffers(1, vplBuffer_.out());
  glNamedBufferStorage(vplBuffer_.get(), vplsPerPass * sizeof(VplTexels), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glCreateTextures(GL_TEXTURE_BUFFER, 1, vplTable_.out());
  glTextureBuffer(vplTable_.get(), GL_RGBA32F, vplBuffer_.get());
  glCreateVertexArrays(1, emptyVao_.out());
  // Reversed-Z with [0,1] clip depth: depth = near / distance keeps float precision at every range.
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glBlendFunc(GL_ONE, GL_ONE);
  glBlendEquation(GL_FUNC_ADD);

  const auto& vpls = in_.vpls.vpls;
  const size_t vplCount = in_.eval.includeVpls ? vpls.size() : 0;
  const size_t lightCount = in_.eval.includeDirect ? in_.scene.lights.size() : 0;
  const size_t totalWork = vplCount + lightCount * vplsPerPass;
  if (vplCount > 0) {
    if (opt_.shadowPcf && opt_.shadowCompare && !contactFlags()) {
      // Sampled through sampler2DShadow: lit (1) where the stored depth ≤ the reference.
      glTextureParameteri(atlas_->texture, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
      glTextureParameteri(atlas_->texture, GL_TEXTURE_COMPARE_FUNC, GL_GEQUAL);
      glTextureParameteri(atlas_->texture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(atlas_->texture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    }
    // A pass over zero VPLs (adds 0): llvmpipe compiles the accumulation shader for this state at its
    // first draw, which then counts as setup, not as the first batch's accumulation.
    lightMapPassState();
    accumulateVplBatch(0, 0, *atlas_);
  }
  checkGlError("GL backend setup");
  finishStage(stats_.setupSeconds, sw);

  if (vplCount > 0) {
    const DepthAtlas& atlas = *atlas_;
    int passesSinceFold = 0;
    for (size_t first = 0; first < vplCount; first += vplsPerPass) {
      const size_t count = std::min<size_t>(vplsPerPass, vplCount - first);
      shadowPassState();
      gpuTimer_.begin(&stats_.gpuShadowSeconds);
      renderVplBatch(first, count, atlas);
      finishStage(stats_.shadowSeconds, sw, &stats_.shadowCpuSeconds);
      lightMapPassState();
      gpuTimer_.begin(&stats_.gpuAccumulateSeconds);
      accumulateVplBatch(first, count, atlas);
      gpuTimer_.end();
      finishStage(stats_.accumulateSeconds, sw, &stats_.accumulateCpuSeconds);
      ++stats_.passes;
      stats_.vpls += count;
      if (++passesSinceFold >= std::max(1, opt_.foldEveryPasses)) {
        gpuTimer_.begin(&stats_.gpuFoldSeconds);
        for (auto& page : pages_) page->fold();
        gpuTimer_.end();
        passesSinceFold = 0;
        finishStage(stats_.foldSeconds, sw);
      }
      if (in_.progress) in_.progress("gl", double(first + count) / std::max<size_t>(1, totalWork));
    }
  }
  for (size_t i = 0; i < lightCount; ++i) {
    if (in_.eval.directIncludes(i) && reachesScene(i)) bakeDirect(in_.scene.lights[i]);
    ++stats_.passes;
    if (in_.progress) in_.progress("gl", double(vplCount + (i + 1) * vplsPerPass) / std::max<size_t>(1, totalWork));
  }
  sw.reset();
  gpuTimer_.begin(&stats_.gpuFoldSeconds);
  for (auto& page : pages_) page->fold();
  gpuTimer_.end();
  checkGlError("GL backend passes");
  finishStage(stats_.foldSeconds, sw);
  gpuTimer_.resolve();

  Stopwatch readWatch;
  std::vector<Lightmap> maps = readMaps();
  stats_.readSeconds += readWatch.seconds();
  if (in_.progress) in_.progress("gl", 1.0);
  return maps;
}

// The contact texels again by the contact evaluator on the same VPLs and lights (the clamped sum, as here),
// over those texels only: its values replace what the shadow maps gave them (and their L1 pages, l1 ≠ null).
void resolveContactTexels(const Evaluator& contacts, const BakeInputs& in,
                          const std::vector<std::vector<uint8_t>>& contact, std::vector<Lightmap>& maps, L1Pages* l1,
                          GlBakeStats& stats) {
  size_t count = 0;
  for (const auto& page : contact) count += static_cast<size_t>(std::count(page.begin(), page.end(), uint8_t{1}));
  stats.contactTexels += count;
  if (count == 0) return;
  Stopwatch watch;
  const BakeInputs quiet{in.scene, in.rayTracer, in.texels, in.vpls, in.eval, {}};  // its progress is this call's
  EvaluationRequest request;
  request.texelSubset = &contact;
  L1Pages tracedL1;
  if (l1) request.directional = &tracedL1;
  const std::vector<Lightmap> traced = contacts.evaluate(quiet, request);
  for (size_t p = 0; p < maps.size() && p < traced.size(); ++p)
    for (size_t i = 0; i < maps[p].size(); ++i) {
      if (!contact[p][i] || !traced[p].valid[i]) continue;
      maps[p].texels[i] = traced[p].texels[i];
      if (l1)
        for (int k = 0; k < 3; ++k) (*l1)[k][p].texels[i] = tracedL1[k][p].texels[i];
    }
  stats.contactSeconds += watch.seconds();
}

}  // namespace

GlEvaluator::GlEvaluator(const GlBackendOptions& options, const Evaluator* contacts)
    : options_(options), contacts_(contacts), stats_(options.stats ? options.stats : &ownStats_) {
  if (!contacts_) options_.resolveContacts = false;
}

std::vector<Lightmap> GlEvaluator::evaluate(const BakeInputs& inputs, const EvaluationRequest& request) const {
  GlBakeStats stats;
  Stopwatch contextTime;
  std::unique_ptr<GlContext> owned;
  const GlContext* ctx = options_.context;
  if (ctx)
    ctx->makeCurrent();
  else
    ctx = (owned = std::make_unique<GlContext>()).get();
  const double contextSeconds = contextTime.seconds();
  stats.renderer = ctx->description();
  if (!options_.context) log::info("GL backend: " + stats.renderer);  // a caller passing a context logs it once
  std::vector<Lightmap> maps;
  std::vector<std::vector<uint8_t>> contact;
  {
    GlBaker baker(inputs, options_, request, stats, *ctx);
    maps = baker.run();
    contact = baker.contactTexels();
  }
  stats.setupSeconds += contextSeconds;
  ++stats.calls;
  if (options_.resolveContacts) resolveContactTexels(*contacts_, inputs, contact, maps, request.directional, stats);
  stats_->add(stats);
  return maps;
}

nlohmann::json GlEvaluator::stats() const {
  return {{"renderer", stats_->renderer}, {"counts", stats_->toJson()}, {"timings", stats_->timingsJson()}};
}

std::vector<EvaluatorChoice> GlEvaluator::settle(const BakeInputs& inputs) {
  if (options_.cubeFaceSize) return {};
  options_.cubeFaceSize = chooseCubeFaceSize(inputs.vpls.vpls, inputs.texels, inputs.eval.clampBound,
                                             options_.cubeFootprintPerTexel, options_.minCubeFaceSize,
                                             options_.maxCubeFaceSize)
                              .size;
  return {{"cube-face", *options_.cubeFaceSize, "a shadow texel's footprint held to the light-map texel spacing"}};
}

void GlEvaluator::describe(nlohmann::json& report) const {
  report["renderer"] = stats_->renderer;
  report["gl"] = stats_->toJson();
  report["timings"]["gl"] = stats_->timingsJson();
}

nlohmann::json GlEvaluator::counts() const {
  nlohmann::json counts = stats_->toJson();
  counts["texelsEvaluated"] = stats_->texelsEvaluated;
  return counts;
}

void GlEvaluator::addCounts(const nlohmann::json& counts) { stats_->addCounts(counts); }

}  // namespace irbake
