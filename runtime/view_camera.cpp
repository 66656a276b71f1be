#include "view_camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

namespace irbake::view {
namespace {

constexpr float kPi = 3.14159265358979f;

// Near plane as a fraction of the scene size: small enough to stand inside a room, large enough that a
// 24-bit depth buffer still separates walls.
float sceneNear(const Bounds3& b) { return std::max(1e-4f, 1e-3f * std::max(b.diagonal(), 1e-3f)); }

glm::mat4 poseLookingAt(const glm::vec3& eye, const glm::vec3& target) {
  glm::vec3 dir = target - eye;
  if (glm::length(dir) < 1e-12f) dir = glm::vec3(0, 0, -1);
  dir = glm::normalize(dir);
  // Looking straight up or down: +Y cannot be the up vector, use -Z instead.
  glm::vec3 up = std::abs(dir.y) > 0.999f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  return glm::inverse(glm::lookAt(eye, eye + dir, up));
}

// Rotation part of a pose with any node scale removed.
glm::quat rotationOf(const glm::mat4& m) {
  glm::mat3 r(m);
  for (int i = 0; i < 3; ++i) r[i] = glm::normalize(r[i]);
  return glm::normalize(glm::quat_cast(r));
}

}  // namespace

glm::mat4 ViewCamera::view() const { return glm::inverse(cameraToWorld); }

glm::mat4 ViewCamera::projection(float aspect) const {
  if (zfar > znear) return glm::perspective(yfov, aspect, znear, zfar);
  return glm::infinitePerspective(yfov, aspect, znear);
}

ViewCamera fromGltfCamera(const Camera& camera, const Bounds3& sceneBounds) {
  ViewCamera v;
  glm::vec3 eye(camera.cameraToWorld[3]);
  v.cameraToWorld = glm::translate(glm::mat4(1.0f), eye) * glm::mat4_cast(rotationOf(camera.cameraToWorld));
  v.yfov = camera.yfov > 0.0f ? camera.yfov : 0.8f;
  v.znear = std::max(camera.znear, 1e-2f * sceneNear(sceneBounds));
  v.zfar = camera.zfar;
  return v;
}

ViewCamera lookAt(const glm::vec3& eye, const glm::vec3& target, float yfovDegrees, const Bounds3& sceneBounds) {
  ViewCamera v;
  v.cameraToWorld = poseLookingAt(eye, target);
  v.yfov = glm::radians(std::clamp(yfovDegrees, 1.0f, 170.0f));
  v.znear = sceneNear(sceneBounds);
  v.zfar = 0.0f;
  return v;
}

ViewCamera orbit(const Bounds3& sceneBounds, float t) {
  Bounds3 b = sceneBounds.valid() ? sceneBounds : Bounds3{glm::vec3(-1), glm::vec3(1)};
  glm::vec3 centre = 0.5f * (b.min + b.max);
  float radius = std::max(0.5f * b.diagonal(), 1e-3f);
  const float fov = 45.0f;
  float distance = 1.15f * radius / std::sin(glm::radians(fov) * 0.5f);
  float a = 2.0f * kPi * t;
  glm::vec3 eye = centre + distance * glm::normalize(glm::vec3(std::sin(a), 0.35f, std::cos(a)));
  return lookAt(eye, centre, fov, b);
}

ViewCamera overview(const Bounds3& sceneBounds) { return orbit(sceneBounds, 0.06f); }

ViewCamera walkthroughFrame(const Scene& scene, int i, int n) {
  Bounds3 b = scene.bounds();
  if (scene.cameras.size() < 2) return orbit(b, n > 0 ? static_cast<float>(i) / n : 0.0f);
  const int k = static_cast<int>(scene.cameras.size());
  float s = n > 1 ? static_cast<float>(i) / (n - 1) * (k - 1) : 0.0f;
  int seg = std::clamp(static_cast<int>(std::floor(s)), 0, k - 2);
  float f = std::clamp(s - seg, 0.0f, 1.0f);
  ViewCamera a = fromGltfCamera(scene.cameras[seg], b), c = fromGltfCamera(scene.cameras[seg + 1], b);
  ViewCamera v = a;
  glm::vec3 eye = glm::mix(a.position(), c.position(), f);
  glm::quat q = glm::slerp(rotationOf(a.cameraToWorld), rotationOf(c.cameraToWorld), f);
  v.cameraToWorld = glm::translate(glm::mat4(1.0f), eye) * glm::mat4_cast(q);
  v.yfov = glm::mix(a.yfov, c.yfov, f);
  v.znear = std::min(a.znear, c.znear);
  v.zfar = (a.zfar > 0 && c.zfar > 0) ? std::max(a.zfar, c.zfar) : 0.0f;
  return v;
}

void FlyCamera::setFrom(const ViewCamera& camera) {
  position = camera.position();
  glm::vec3 f = camera.forward();
  pitch = std::asin(std::clamp(f.y, -1.0f, 1.0f));
  yaw = std::atan2(-f.x, -f.z);
  look(0.0f, 0.0f);  // clamp the pitch
  yfov = camera.yfov;
  znear = camera.znear;
  zfar = camera.zfar;
}

ViewCamera FlyCamera::camera() const {
  glm::vec3 forward(-std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch));
  ViewCamera v;
  v.cameraToWorld = glm::inverse(glm::lookAt(position, position + forward, glm::vec3(0, 1, 0)));
  v.yfov = yfov;
  v.znear = znear;
  v.zfar = zfar;
  return v;
}

void FlyCamera::move(const glm::vec3& d) {
  glm::vec3 forward(-std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch));
  glm::vec3 right(std::cos(yaw), 0.0f, -std::sin(yaw));
  position += d.x * right + d.y * glm::vec3(0, 1, 0) + d.z * forward;
}

void FlyCamera::look(float dyaw, float dpitch) {
  yaw += dyaw;
  const float limit = glm::radians(89.0f);
  pitch = std::clamp(pitch + dpitch, -limit, limit);
}

}  // namespace irbake::view
