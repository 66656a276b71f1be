// The viewer's camera: a pose (camera-to-world, looking down -Z, +Y up as in glTF) and a lens.
// Built from a glTF camera, from eye/target/fov, from an orbit or a path along the glTF cameras.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace irbake::view {

struct ViewCamera {
  glm::mat4 cameraToWorld{1.0f};  // looks down -Z, +Y up (glTF convention)
  float yfov = 0.8f;              // vertical field of view, radians
  float znear = 0.01f;            // near plane distance (m)
  float zfar = 0.0f;              // far plane distance (m); 0 = infinite

  glm::vec3 position() const { return glm::vec3(cameraToWorld[3]); }
  glm::vec3 forward() const { return -glm::normalize(glm::vec3(cameraToWorld[2])); }
  glm::mat4 view() const;
  glm::mat4 projection(float aspect) const;
};

// A glTF camera as loaded; the near plane is raised to a scene-scaled minimum so depth stays usable.
ViewCamera fromGltfCamera(const Camera& camera, const Bounds3& sceneBounds);
// Looking from eye at target with a vertical fov in degrees; near/far follow the scene size.
ViewCamera lookAt(const glm::vec3& eye, const glm::vec3& target, float yfovDegrees, const Bounds3& sceneBounds);
// A view of the whole scene from outside (used when the scene has no camera).
ViewCamera overview(const Bounds3& sceneBounds);
// Orbit around the scene centre at parameter t in [0,1) (one full turn), slightly above it.
ViewCamera orbit(const Bounds3& sceneBounds, float t);
// Frame i of n of a walkthrough: along the glTF cameras (position lerp, orientation slerp, fov lerp)
// when the scene has two or more, else an orbit.
ViewCamera walkthroughFrame(const Scene& scene, int i, int n);

// A fly camera for the window: position, yaw and pitch, speed scaled to the scene.
struct FlyCamera {
  glm::vec3 position{0.0f};
  float yaw = 0.0f;    // radians about +Y; 0 looks down -Z
  float pitch = 0.0f;  // radians, clamped to ±89°
  float yfov = 0.8f, znear = 0.01f, zfar = 0.0f;

  void setFrom(const ViewCamera& camera);
  ViewCamera camera() const;
  // Moves in the camera's frame: x right, y up (world), z forward; distances in metres.
  void move(const glm::vec3& rightUpForward);
  void look(float dyaw, float dpitch);
};

}  // namespace irbake::view
