#include "raytrace/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "common/error.h"

namespace irbake {

namespace {

// Alpha MASK cut-outs: a hit whose textured alpha is below the cutoff is not a hit (a hole).
struct MaskGeometry {
  const Scene* scene = nullptr;
  const Primitive* prim = nullptr;
};

void alphaMaskFilter(const RTCFilterFunctionNArguments* args) {
  const auto* mask = static_cast<const MaskGeometry*>(args->geometryUserPtr);
  const Material& m = mask->scene->materials[mask->prim->material];
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    uint32_t tri = RTCHitN_primID(args->hit, args->N, i);
    glm::vec2 b(RTCHitN_u(args->hit, args->N, i), RTCHitN_v(args->hit, args->N, i));
    if (mask->scene->baseColorAt(*mask->prim, tri, b).a < m.alphaCutoff) args->valid[i] = 0;
  }
}

// See-through surfaces (BLEND, KHR_materials_transmission) never occlude: occlusion queries skip them
// and callers multiply by RayTracer::transmittance() along the unoccluded ray. Intersections see them.
void seeThroughOcclusionFilter(const RTCFilterFunctionNArguments* args) {
  for (unsigned i = 0; i < args->N; ++i) args->valid[i] = 0;
}

void errorCallback(void*, RTCError code, const char* str) {
  // Embree errors during construction are turned into exceptions by the checks below; log nothing here.
  (void)code;
  (void)str;
}

// Lane k of an 8-wide ray packet: from origin along dir over [0, tmax], every mask bit.
void setPacketLane(RTCRay8& packet, size_t k, const glm::vec3& origin, const glm::vec3& dir, float tmax) {
  packet.org_x[k] = origin.x; packet.org_y[k] = origin.y; packet.org_z[k] = origin.z;
  packet.dir_x[k] = dir.x; packet.dir_y[k] = dir.y; packet.dir_z[k] = dir.z;
  packet.tnear[k] = 0.0f;
  packet.tfar[k] = tmax;
  packet.time[k] = 0.0f;
  packet.mask[k] = 0xFFFFFFFFu;
  packet.id[k] = static_cast<unsigned>(k);
  packet.flags[k] = 0;
}

}  // namespace

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  RTCScene fastScene = nullptr;  // the same geometries without RTC_SCENE_FLAG_ROBUST (Traversal::Fast)
  std::vector<MaskGeometry> masks;  // one per primitive (stable addresses: sized before use)
  std::vector<glm::vec3> faceNormals;  // per primitive, per triangle: unit geometric normal
  std::vector<size_t> faceOffset;      // primitive -> first index in faceNormals
  bool packets8 = false;               // native rtcOccluded8 support
  ~Impl() {
    if (fastScene) rtcReleaseScene(fastScene);
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

RayTracer::RayTracer(const Scene& scene) : impl_(std::make_unique<Impl>()), scene_(scene) {
  Impl& I = *impl_;
  I.device = rtcNewDevice(nullptr);
  if (!I.device) throw Error(ErrorCode::InvalidData, scene.sourcePath, "cannot create the Embree device");
  rtcSetDeviceErrorFunction(I.device, errorCallback, nullptr);
  I.scene = rtcNewScene(I.device);
  // Robust traversal: rays that graze edges between triangles do not slip through (energy closure).
  rtcSetSceneFlags(I.scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(I.scene, RTC_BUILD_QUALITY_HIGH);
  I.fastScene = rtcNewScene(I.device);
  rtcSetSceneBuildQuality(I.fastScene, RTC_BUILD_QUALITY_HIGH);

  // Offsets: relative to the larger of the scene size and its distance from the origin, since float
  // spacing grows with the coordinate magnitude (huge scale ranges).
  Bounds3 b = scene.bounds();
  float extent = b.valid() ? b.diagonal() : 1.0f;
  float magnitude = b.valid() ? std::max(glm::length(b.min), glm::length(b.max)) : 1.0f;
  epsilon_ = std::max(1e-5f * std::max(extent, 1e-3f), 4e-7f * magnitude);

  I.masks.resize(scene.primitives.size());
  I.faceOffset.resize(scene.primitives.size() + 1, 0);
  for (size_t p = 0; p < scene.primitives.size(); ++p) I.faceOffset[p + 1] = I.faceOffset[p] + scene.primitives[p].triangleCount();
  I.faceNormals.resize(I.faceOffset.back());

  for (size_t p = 0; p < scene.primitives.size(); ++p) {
    const Primitive& prim = scene.primitives[p];
    size_t nt = prim.triangleCount();
    for (size_t t = 0; t < nt; ++t) {
      const glm::vec3& a = prim.positions[prim.indices[3 * t]];
      const glm::vec3& c1 = prim.positions[prim.indices[3 * t + 1]];
      const glm::vec3& c2 = prim.positions[prim.indices[3 * t + 2]];
      glm::vec3 n = glm::cross(c1 - a, c2 - a);
      float len = glm::length(n);
      I.faceNormals[I.faceOffset[p] + t] = len > 0.0f ? n / len : glm::vec3(0.0f, 0.0f, 1.0f);
    }
    if (nt == 0 || prim.positions.empty()) continue;
    for (uint32_t idx : prim.indices)
      if (idx >= prim.positions.size())
        throw Error(ErrorCode::InvalidData, scene.sourcePath, "primitive '" + prim.name + "' has an index out of range");
    RTCGeometry g = rtcNewGeometry(I.device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), prim.positions.size()));
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(uint32_t), nt));
    if (!vb || !ib) {
      rtcReleaseGeometry(g);
      throw Error(ErrorCode::InvalidData, scene.sourcePath, "Embree could not allocate buffers for '" + prim.name + "'");
    }
    for (size_t v = 0; v < prim.positions.size(); ++v) {
      vb[3 * v] = prim.positions[v].x;
      vb[3 * v + 1] = prim.positions[v].y;
      vb[3 * v + 2] = prim.positions[v].z;
    }
    std::copy(prim.indices.begin(), prim.indices.end(), ib);
    const Material& material = scene.materials[prim.material];
    if (material.alphaMode == AlphaMode::Mask) {
      I.masks[p] = MaskGeometry{&scene, &prim};
      rtcSetGeometryUserData(g, &I.masks[p]);
      rtcSetGeometryIntersectFilterFunction(g, alphaMaskFilter);
      rtcSetGeometryOccludedFilterFunction(g, alphaMaskFilter);
    }
    if (material.isTransmissive()) {
      rtcSetGeometryOccludedFilterFunction(g, seeThroughOcclusionFilter);
      hasTransmission_ = true;
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(I.scene, g, static_cast<unsigned>(p));  // geomID = primitive index
    rtcAttachGeometryByID(I.fastScene, g, static_cast<unsigned>(p));
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(I.scene);
  rtcCommitScene(I.fastScene);
  I.packets8 = rtcGetDeviceProperty(I.device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
  if (rtcGetDeviceError(I.device) != RTC_ERROR_NONE)
    throw Error(ErrorCode::InvalidData, scene.sourcePath, "Embree failed to build the scene");
}

RayTracer::~RayTracer() = default;

RayHit RayTracer::intersect(const glm::vec3& origin, const glm::vec3& dir, float tmin, float tmax) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = origin.x; rh.ray.org_y = origin.y; rh.ray.org_z = origin.z;
  rh.ray.dir_x = dir.x; rh.ray.dir_y = dir.y; rh.ray.dir_z = dir.z;
  rh.ray.tnear = tmin;
  rh.ray.tfar = tmax;
  rh.ray.time = 0.0f;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return RayHit{};
  return completeHit(dir, rh.ray.tfar, rh.hit.geomID, rh.hit.primID, glm::vec2(rh.hit.u, rh.hit.v));
}

void RayTracer::intersectPackets(const glm::vec3& origin, const glm::vec3* dirs, size_t n, RayHit* hits,
                                 HitDetail detail, Traversal traversal) const {
  RTCScene scene = traversal == Traversal::Fast ? impl_->fastScene : impl_->scene;
  if (!impl_->packets8) {
    for (size_t i = 0; i < n; ++i) hits[i] = intersect(origin, dirs[i], 0.0f, 1e30f);
    return;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  for (size_t base = 0; base < n; base += 8) {
    alignas(32) RTCRayHit8 packet;
    alignas(32) int valid[8];
    const size_t count = std::min<size_t>(8, n - base);
    for (size_t k = 0; k < 8; ++k) {
      valid[k] = k < count ? -1 : 0;
      setPacketLane(packet.ray, k, origin, dirs[base + std::min(k, count - 1)], 1e30f);
      packet.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
      packet.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, scene, &ctx, &packet);
    for (size_t k = 0; k < count; ++k)
      hits[base + k] = packet.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID
                           ? RayHit{}
                           : completeHit(dirs[base + k], packet.ray.tfar[k], packet.hit.geomID[k], packet.hit.primID[k],
                                         glm::vec2(packet.hit.u[k], packet.hit.v[k]), detail);
  }
}

RayHit RayTracer::completeHit(const glm::vec3& dir, float t, uint32_t geomID, uint32_t primID, glm::vec2 uv,
                              HitDetail detail) const {
  RayHit out;
  out.hit = true;
  out.t = t;
  out.primitive = geomID;
  out.triangle = primID;
  out.barycentric = uv;
  if (detail == HitDetail::Surface) {
    out.geometricNormal = impl_->faceNormals[impl_->faceOffset[out.primitive] + out.triangle];
    out.backFace = glm::dot(dir, out.geometricNormal) > 0.0f;
    return out;
  }
  const Primitive& prim = scene_.primitives[out.primitive];
  const uint32_t* idx = &prim.indices[3 * out.triangle];
  float w = 1.0f - out.barycentric.x - out.barycentric.y;
  // Position from the barycentrics (more accurate on the surface than origin + t·dir).
  out.position = prim.positions[idx[0]] * w + prim.positions[idx[1]] * out.barycentric.x + prim.positions[idx[2]] * out.barycentric.y;
  out.geometricNormal = impl_->faceNormals[impl_->faceOffset[out.primitive] + out.triangle];
  if (prim.normals.size() == prim.positions.size()) {
    glm::vec3 n = prim.normals[idx[0]] * w + prim.normals[idx[1]] * out.barycentric.x + prim.normals[idx[2]] * out.barycentric.y;
    float len = glm::length(n);
    out.shadingNormal = len > 0.0f ? n / len : out.geometricNormal;
  } else {
    out.shadingNormal = out.geometricNormal;
  }
  out.backFace = glm::dot(dir, out.geometricNormal) > 0.0f;
  return out;
}

bool RayTracer::occluded(const glm::vec3& origin, const glm::vec3& dir, float tmin, float tmax) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRay ray;
  ray.org_x = origin.x; ray.org_y = origin.y; ray.org_z = origin.z;
  ray.dir_x = dir.x; ray.dir_y = dir.y; ray.dir_z = dir.z;
  ray.tnear = tmin;
  ray.tfar = tmax;
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &ctx, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on an occlusion
}

glm::vec3 RayTracer::transmittance(const glm::vec3& origin, const glm::vec3& dir, float tmin, float tmax) const {
  glm::vec3 t(1.0f);
  if (!hasTransmission_) return t;
  float start = tmin;
  for (int layer = 0; layer < 64 && start < tmax; ++layer) {
    const RayHit hit = intersect(origin, dir, start, tmax);
    if (!hit.hit) return t;
    const Primitive& prim = scene_.primitives[hit.primitive];
    const SurfaceTransmission s = scene_.transmissionAt(prim, hit.triangle, hit.barycentric);
    if (s.fraction <= 0.0f) return glm::vec3(0.0f);  // an opaque surface after all (rounding at tmax)
    t *= s.transmittance();
    if (glm::max(t.x, glm::max(t.y, t.z)) <= 0.0f) return t;
    start = hit.t + epsilon_;
  }
  return t;
}

bool RayTracer::visibilityRay(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb,
                              ShadowRay& ray) const {
  // Offset each end along its normal towards the other point's side, so rays leave the surface
  // they start on and stop short of the one they end on.
  glm::vec3 d0 = b - a;
  glm::vec3 pa = a + na * (glm::dot(na, d0) >= 0.0f ? epsilon_ : -epsilon_);
  glm::vec3 pb = b + nb * (glm::dot(nb, d0) <= 0.0f ? epsilon_ : -epsilon_);
  glm::vec3 d = pb - pa;
  float dist = glm::length(d);
  if (!(dist > epsilon_)) return false;
  ray.origin = pa;
  ray.dir = d / dist;
  ray.tmax = dist - epsilon_;
  return true;
}

bool RayTracer::visible(const glm::vec3& a, const glm::vec3& na, const glm::vec3& b, const glm::vec3& nb) const {
  ShadowRay ray;
  if (!visibilityRay(a, na, b, nb, ray)) return true;
  return !occluded(ray.origin, ray.dir, 0.0f, ray.tmax);
}

void RayTracer::occludedPackets(const ShadowRay* rays, size_t n, uint8_t* occluded) const {
  if (!impl_->packets8) {  // this Embree build has no 8-wide packets: single rays
    for (size_t i = 0; i < n; ++i) occluded[i] = this->occluded(rays[i].origin, rays[i].dir, 0.0f, rays[i].tmax) ? 1 : 0;
    return;
  }
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  for (size_t base = 0; base < n; base += 8) {
    alignas(32) RTCRay8 packet;
    alignas(32) int valid[8];
    size_t count = std::min<size_t>(8, n - base);
    for (size_t k = 0; k < 8; ++k) {
      const ShadowRay& r = rays[base + std::min(k, count - 1)];
      valid[k] = k < count ? -1 : 0;
      setPacketLane(packet, k, r.origin, r.dir, r.tmax);
    }
    rtcOccluded8(valid, impl_->scene, &ctx, &packet);
    for (size_t k = 0; k < count; ++k) occluded[base + k] = packet.tfar[k] < 0.0f ? 1 : 0;
  }
}

glm::vec3 RayTracer::insetPoint(uint32_t primitive, uint32_t triangle, const glm::vec3& p) const {
  const Primitive& prim = scene_.primitives[primitive];
  const uint32_t* idx = &prim.indices[3 * triangle];
  glm::vec3 c = (prim.positions[idx[0]] + prim.positions[idx[1]] + prim.positions[idx[2]]) / 3.0f;
  glm::vec3 d = c - p;
  float len = glm::length(d);
  if (!(len > 0.0f)) return p;
  return p + d * (std::min(epsilon_, 0.5f * len) / len);
}

glm::vec3 RayTracer::albedoAt(const RayHit& hit) const {
  if (!hit.hit) return glm::vec3(0.0f);
  return glm::vec3(scene_.baseColorAt(scene_.primitives[hit.primitive], hit.triangle, hit.barycentric));
}

}  // namespace irbake
