// Camera maths: glTF poses, look-at, walkthrough interpolation, the fly camera round trip.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "view_camera.h"

namespace irbake::view {
namespace {

void expectNear(glm::vec3 a, glm::vec3 b, float tol, const char* what) {
  EXPECT_NEAR(glm::length(a - b), 0.0f, tol) << what << ": (" << a.x << "," << a.y << "," << a.z << ") vs (" << b.x
                                             << "," << b.y << "," << b.z << ")";
}

Scene twoCameraScene() {
  Scene s;
  Primitive p;
  p.positions = {{-1, 0, -1}, {1, 0, -1}, {0, 1, 1}};
  p.indices = {0, 1, 2};
  s.primitives.push_back(p);
  s.materials.emplace_back();
  Camera a, b;
  a.cameraToWorld = glm::translate(glm::mat4(1.0f), glm::vec3(0, 1, 5));  // looks down -Z
  a.yfov = 0.6f;
  // Scaled node (×2) turned 90° about +Y: looks down -X; the scale must not leak into the view.
  b.cameraToWorld = glm::translate(glm::mat4(1.0f), glm::vec3(4, 1, 1)) *
                    glm::rotate(glm::mat4(1.0f), 1.5707963f, glm::vec3(0, 1, 0)) * glm::scale(glm::mat4(1.0f), glm::vec3(2.0f));
  b.yfov = 1.0f;
  s.cameras = {a, b};
  return s;
}

TEST(ViewCamera, GltfCameraDropsNodeScaleAndKeepsPose) {
  Scene s = twoCameraScene();
  ViewCamera b = fromGltfCamera(s.cameras[1], s.bounds());
  expectNear(b.position(), {4, 1, 1}, 1e-5f, "position");
  expectNear(b.forward(), {-1, 0, 0}, 1e-5f, "forward");
  EXPECT_NEAR(glm::length(glm::vec3(b.cameraToWorld[0])), 1.0f, 1e-5f);
  // The view matrix maps the camera's own position to the origin and a point ahead to -Z.
  glm::vec4 ahead = b.view() * glm::vec4(2, 1, 1, 1);
  EXPECT_NEAR(ahead.x, 0.0f, 1e-5f);
  EXPECT_NEAR(ahead.z, -2.0f, 1e-5f);
}

TEST(ViewCamera, WalkthroughRunsFromFirstToLastCamera) {
  Scene s = twoCameraScene();
  ViewCamera first = walkthroughFrame(s, 0, 5), last = walkthroughFrame(s, 4, 5), mid = walkthroughFrame(s, 2, 5);
  expectNear(first.position(), {0, 1, 5}, 1e-5f, "first");
  expectNear(last.position(), {4, 1, 1}, 1e-5f, "last");
  expectNear(mid.position(), {2, 1, 3}, 1e-5f, "middle: position lerp");
  // Slerp halfway between -Z and -X: the bisector.
  expectNear(mid.forward(), glm::normalize(glm::vec3(-1, 0, -1)), 1e-4f, "middle: orientation slerp");
  EXPECT_NEAR(mid.yfov, 0.8f, 1e-5f);
}

TEST(ViewCamera, OrbitKeepsItsDistanceAndLooksAtTheCentre) {
  Bounds3 b{glm::vec3(-1, 0, -2), glm::vec3(3, 2, 2)};
  glm::vec3 centre(1, 1, 0);
  float d0 = glm::length(orbit(b, 0.0f).position() - centre);
  for (float t : {0.1f, 0.37f, 0.8f}) {
    ViewCamera c = orbit(b, t);
    EXPECT_NEAR(glm::length(c.position() - centre), d0, 1e-4f * d0);
    expectNear(c.forward(), glm::normalize(centre - c.position()), 1e-5f, "looks at the centre");
  }
  Scene one;  // fewer than two cameras: the walkthrough orbits
  one.primitives.push_back(twoCameraScene().primitives[0]);
  EXPECT_NE(walkthroughFrame(one, 0, 4).position(), walkthroughFrame(one, 1, 4).position());
}

TEST(ViewCamera, FlyCameraRoundTripAndMoves) {
  Bounds3 b{glm::vec3(-5), glm::vec3(5)};
  ViewCamera start = lookAt({1, 2, 3}, {0, 1, -1}, 50.0f, b);
  FlyCamera fly;
  fly.setFrom(start);
  ViewCamera again = fly.camera();
  expectNear(again.position(), start.position(), 1e-5f, "position");
  expectNear(again.forward(), start.forward(), 1e-5f, "forward");
  EXPECT_NEAR(again.yfov, glm::radians(50.0f), 1e-6f);
  fly.move({0, 0, 2});  // 2 m forward
  expectNear(fly.position, start.position() + 2.0f * start.forward(), 1e-5f, "forward move");
  fly.look(0.0f, 10.0f);  // pitch clamps below straight up
  EXPECT_LT(fly.camera().forward().y, 1.0f);
  EXPECT_GT(fly.camera().forward().y, 0.99f);
}

}  // namespace
}  // namespace irbake::view
