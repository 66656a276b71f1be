#include "samples/sample_scenes.h"

#include <cmath>
#include <fstream>
#include <iterator>
#include <memory>

#include <glm/gtc/matrix_transform.hpp>

#include "common/error.h"
#include "common/output_guard.h"
#include "export/gltf_writer.h"

namespace irbake::samples {

namespace {

constexpr float kPi = 3.14159265358979323846f;

// Assembles a scene from quads, one primitive per named part.
class SceneBuilder {
 public:
  int material(const std::string& name, glm::vec3 albedo, glm::vec3 emission = glm::vec3(0.0f)) {
    Material m;
    m.name = name;
    m.baseColorFactor = glm::vec4(albedo, 1.0f);
    m.emissiveFactor = emission;
    scene.materials.push_back(m);
    return static_cast<int>(scene.materials.size()) - 1;
  }

  Primitive& part(const std::string& name, int material) {
    Primitive p;
    p.name = name;
    p.material = material;
    scene.primitives.push_back(p);
    return scene.primitives.back();
  }

  // Quad a-b-c-d (in order around its edge; planar), front face towards `facing` (a direction).
  // UV0 runs (0,0) (1,0) (1,1) (0,1) over a, b, c, d.
  static void quad(Primitive& p, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 facing) {
    glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    bool flip = glm::dot(n, facing) < 0.0f;
    if (flip) n = -n;
    uint32_t base = static_cast<uint32_t>(p.positions.size());
    p.positions.insert(p.positions.end(), {a, b, c, d});
    p.normals.insert(p.normals.end(), {n, n, n, n});
    p.uv0.insert(p.uv0.end(), {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(1, 1), glm::vec2(0, 1)});
    if (!flip) p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    else p.indices.insert(p.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  }

  // Quad facing towards (inside) or away from (outside) a reference point.
  static void quadToward(Primitive& p, glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 point, bool toward = true) {
    glm::vec3 centre = 0.25f * (a + b + c + d);
    quad(p, a, b, c, d, toward ? point - centre : centre - point);
  }

  // Axis-aligned box interior (six walls, normals inward) on one primitive.
  static void boxInside(Primitive& p, glm::vec3 lo, glm::vec3 hi) {
    glm::vec3 c = 0.5f * (lo + hi);
    auto v = [&](int i) { return glm::vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    for (const auto& f : faces) quadToward(p, v(f[0]), v(f[1]), v(f[2]), v(f[3]), c);
  }

  Scene finish() {
    scene.stats.trianglesKept = scene.triangleCount();
    return std::move(scene);
  }

  Scene scene;
};

Light pointLight(const std::string& name, glm::vec3 position, float intensity) {
  Light l;
  l.name = name;
  l.type = LightType::Point;
  l.position = position;
  l.intensity = intensity;
  return l;
}

// Point-to-parallel-rectangle form factor with the normal through a corner; X, Y = sides / height.
double cornerFormFactor(double X, double Y) {
  double ax = std::sqrt(1.0 + X * X), ay = std::sqrt(1.0 + Y * Y);
  return (X / ax * std::atan(Y / ax) + Y / ay * std::atan(X / ay)) / (2.0 * M_PI);
}

}  // namespace

double parallelRectangleIrradianceOverPi(double px, double pz, double x0, double x1, double z0, double z1, double h, double Le) {
  auto g = [&](double a, double b) {
    double s = (a < 0 ? -1.0 : 1.0) * (b < 0 ? -1.0 : 1.0);
    return s * cornerFormFactor(std::abs(a) / h, std::abs(b) / h);
  };
  double F = g(x1 - px, z1 - pz) - g(x0 - px, z1 - pz) - g(x1 - px, z0 - pz) + g(x0 - px, z0 - pz);
  return Le * F;
}

Scene makeCornellBox() {
  SceneBuilder b;
  const float mm = 0.001f;
  auto P = [&](float x, float y, float z) { return glm::vec3(x, y, z) * mm; };
  const glm::vec3 inside = P(278.0f, 274.4f, 279.6f);
  const int white = b.material("white", {0.725f, 0.71f, 0.68f});
  const int red = b.material("red", {0.63f, 0.065f, 0.05f});
  const int green = b.material("green", {0.14f, 0.45f, 0.091f});
  const int light = b.material("light", {0.78f, 0.78f, 0.78f}, {17.0f, 12.0f, 4.0f});

  b.quadToward(b.part("floor", white), P(552.8f, 0, 0), P(0, 0, 0), P(0, 0, 559.2f), P(549.6f, 0, 559.2f), inside);
  b.quadToward(b.part("ceiling", white), P(556.0f, 548.8f, 0), P(556.0f, 548.8f, 559.2f), P(0, 548.8f, 559.2f), P(0, 548.8f, 0), inside);
  b.quadToward(b.part("back_wall", white), P(549.6f, 0, 559.2f), P(0, 0, 559.2f), P(0, 548.8f, 559.2f), P(556.0f, 548.8f, 559.2f), inside);
  b.quadToward(b.part("right_wall_green", green), P(0, 0, 559.2f), P(0, 0, 0), P(0, 548.8f, 0), P(0, 548.8f, 559.2f), inside);
  b.quadToward(b.part("left_wall_red", red), P(552.8f, 0, 0), P(549.6f, 0, 559.2f), P(556.0f, 548.8f, 559.2f), P(556.0f, 548.8f, 0), inside);

  // Blocks: four sides and a top each (their bottoms rest on the floor), faces pointing out.
  auto block = [&](const std::string& name, const glm::vec3 (&top)[4], float height) {
    Primitive& p = b.part(name, white);
    glm::vec3 centre = 0.25f * (top[0] + top[1] + top[2] + top[3]);
    centre.y = 0.5f * height;
    b.quadToward(p, top[0], top[1], top[2], top[3], centre, false);
    for (int i = 0; i < 4; ++i) {
      glm::vec3 t0 = top[i], t1 = top[(i + 1) % 4];
      glm::vec3 b0(t0.x, 0.0f, t0.z), b1(t1.x, 0.0f, t1.z);
      b.quadToward(p, b0, t0, t1, b1, centre, false);
    }
  };
  const glm::vec3 shortTop[4] = {P(130, 165, 65), P(82, 165, 225), P(240, 165, 272), P(290, 165, 114)};
  const glm::vec3 tallTop[4] = {P(423, 330, 247), P(265, 330, 296), P(314, 330, 456), P(472, 330, 406)};
  block("short_block", shortTop, 0.165f);
  block("tall_block", tallTop, 0.330f);

  // The light: 130 × 105 mm, 0.5 mm below the ceiling so it is not coplanar with it, facing down.
  const float ly = 548.3f;
  b.quad(b.part("light", light), P(343, ly, 227), P(343, ly, 332), P(213, ly, 332), P(213, ly, 227), glm::vec3(0, -1, 0));

  Camera cam;
  cam.name = "cornell_camera";
  // glTF cameras look down −Z: a half turn about +Y makes the published +Z viewing direction.
  cam.cameraToWorld = glm::translate(glm::mat4(1.0f), P(278, 273, -800)) * glm::rotate(glm::mat4(1.0f), kPi, glm::vec3(0, 1, 0));
  cam.yfov = 2.0f * std::atan(12.5f / 35.0f);
  cam.aspectRatio = 1.0f;
  cam.znear = 0.01f;
  b.scene.cameras.push_back(cam);
  return b.finish();
}

Scene makeContacts() {
  SceneBuilder b;
  const int floorMat = b.material("floor", glm::vec3(0.5f));
  const int wallMat = b.material("wall", glm::vec3(0.7f));
  const int woodMat = b.material("cupboard", {0.6f, 0.45f, 0.3f});
  const int boxMat = b.material("box", {0.3f, 0.5f, 0.7f});
  const int lampMat = b.material("lamp", glm::vec3(0.8f), glm::vec3(8.0f));
  const glm::vec3 lo(0.0f), hi(4.0f, 2.5f, 3.0f), inside = 0.5f * (lo + hi);
  // The room: floor, ceiling and walls as parts of their own (normals inward).
  b.quadToward(b.part("floor", floorMat), {0, 0, 0}, {4, 0, 0}, {4, 0, 3}, {0, 0, 3}, inside);
  b.quadToward(b.part("ceiling", wallMat), {0, 2.5f, 0}, {4, 2.5f, 0}, {4, 2.5f, 3}, {0, 2.5f, 3}, inside);
  Primitive& walls = b.part("walls", wallMat);
  b.quadToward(walls, {0, 0, 0}, {4, 0, 0}, {4, 2.5f, 0}, {0, 2.5f, 0}, inside);
  b.quadToward(walls, {0, 0, 3}, {4, 0, 3}, {4, 2.5f, 3}, {0, 2.5f, 3}, inside);
  b.quadToward(walls, {0, 0, 0}, {0, 0, 3}, {0, 2.5f, 3}, {0, 2.5f, 0}, inside);
  b.quadToward(walls, {4, 0, 0}, {4, 0, 3}, {4, 2.5f, 3}, {4, 2.5f, 0}, inside);
  // Closed boxes with outward faces (bottom included: it lies on the floor plane).
  auto box = [&](const std::string& name, int material, glm::vec3 l, glm::vec3 h) {
    Primitive& p = b.part(name, material);
    const glm::vec3 c = 0.5f * (l + h);
    auto v = [&](int i) { return glm::vec3(i & 1 ? h.x : l.x, i & 2 ? h.y : l.y, i & 4 ? h.z : l.z); };
    const int faces[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    for (const auto& f : faces) b.quadToward(p, v(f[0]), v(f[1]), v(f[2]), v(f[3]), c, false);
  };
  box("cupboard", woodMat, {1.5f, 0.0f, 0.001f}, {2.5f, 2.0f, 0.601f});  // 1 mm in front of the back wall
  box("box", boxMat, {0.6f, 0.0f, 1.6f}, {1.1f, 0.5f, 2.1f});
  const float ly = 2.5f - 1e-4f;  // 0.1 mm under the ceiling
  b.quad(b.part("lamp", lampMat), {1.75f, ly, 1.55f}, {2.25f, ly, 1.55f}, {2.25f, ly, 2.05f}, {1.75f, ly, 2.05f},
         glm::vec3(0, -1, 0));

  Camera cam;
  cam.name = "contacts_camera";
  // From the front wall's side, looking −Z at the cupboard (glTF cameras look down −Z).
  cam.cameraToWorld = glm::translate(glm::mat4(1.0f), glm::vec3(2.0f, 1.4f, 2.95f)) *
                      glm::rotate(glm::mat4(1.0f), -0.25f, glm::vec3(1, 0, 0));
  cam.yfov = 1.2f;
  cam.aspectRatio = 1.0f;
  cam.znear = 0.01f;
  b.scene.cameras.push_back(cam);
  return b.finish();
}

Scene makeFurnace(float rho, float Le) {
  SceneBuilder b;
  int m = b.material("furnace_wall", glm::vec3(rho), glm::vec3(Le));
  b.boxInside(b.part("furnace", m), glm::vec3(-1.0f), glm::vec3(1.0f));
  return b.finish();
}

Scene makePointOverPlane() {
  SceneBuilder b;
  int m = b.material("grey", glm::vec3(0.5f));
  b.quad(b.part("plane", m), {-5, 0, -5}, {5, 0, -5}, {5, 0, 5}, {-5, 0, 5}, {0, 1, 0});
  b.scene.lights.push_back(pointLight("point", {0, 1, 0}, 10.0f));
  return b.finish();
}

Scene makeQuadOverPlane() {
  SceneBuilder b;
  int emitter = b.material("emitter", glm::vec3(0.0f), glm::vec3(1.0f));
  int grey = b.material("grey", glm::vec3(0.5f));
  b.quad(b.part("emitter", emitter), {-0.5f, 1, -0.5f}, {0.5f, 1, -0.5f}, {0.5f, 1, 0.5f}, {-0.5f, 1, 0.5f}, {0, -1, 0});
  b.quad(b.part("receiver", grey), {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, 1, 0});
  return b.finish();
}

Scene makeCorner(float albedo, float spotIntensity) {
  SceneBuilder b;
  int m = b.material("corner", glm::vec3(albedo));
  b.quad(b.part("floor", m), {0, 0, 0}, {3, 0, 0}, {3, 0, 3}, {0, 0, 3}, {0, 1, 0});
  b.quad(b.part("wall", m), {0, 0, 0}, {0, 3, 0}, {0, 3, 3}, {0, 0, 3}, {1, 0, 0});
  Light spot;
  spot.name = "spot";
  spot.type = LightType::Spot;
  spot.position = {2.0f, 2.0f, 1.5f};
  spot.direction = glm::normalize(glm::vec3(0.5f, 0.0f, 1.5f) - spot.position);
  spot.intensity = spotIntensity;
  spot.innerConeAngle = 30.0f * kPi / 180.0f;
  spot.outerConeAngle = 50.0f * kPi / 180.0f;
  b.scene.lights.push_back(spot);
  return b.finish();
}

Scene makeThinWall() {
  SceneBuilder b;
  int m = b.material("wall", glm::vec3(0.5f));
  // Each room is its own primitive so a bake can be scored per room.
  b.boxInside(b.part("room_lit", m), {-2, 0, -1}, {0, 2, 1});
  b.boxInside(b.part("room_dark", m), {0, 0, -1}, {2, 2, 1});
  // boxInside gave each room its own face at x = 0 already: together they are the zero-thickness
  // partition (two coincident quads facing −X and +X).
  b.scene.lights.push_back(pointLight("point", {-1, 1, 0}, 10.0f));
  return b.finish();
}

Scene makeTexturedPlane() {
  SceneBuilder b;
  Texture checker;
  checker.name = "checker";
  checker.width = checker.height = 64;
  checker.texels.resize(64 * 64);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      float a = ((x / 8 + y / 8) % 2 == 0) ? 0.8f : 0.2f;
      checker.texels[y * 64 + x] = glm::vec4(a, a, a, 1.0f);
    }
  b.scene.textures.push_back(checker);
  int m = b.material("checker", glm::vec3(1.0f));
  b.scene.materials[m].baseColorTexture = 0;
  b.quad(b.part("plane", m), {-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}, {0, 1, 0});
  b.scene.lights.push_back(pointLight("point", {0, 1, 0}, 10.0f));
  return b.finish();
}

std::vector<NamedSample> allSamples() {
  std::vector<NamedSample> out;
  out.push_back({"cornell_box", makeCornellBox()});
  out.push_back({"furnace", makeFurnace()});
  out.push_back({"point_over_plane", makePointOverPlane()});
  out.push_back({"quad_over_plane", makeQuadOverPlane()});
  out.push_back({"corner", makeCorner()});
  out.push_back({"thin_wall", makeThinWall()});
  out.push_back({"textured_plane", makeTexturedPlane()});
  out.push_back({"contacts", makeContacts()});
  return out;
}

namespace {

// True when f.finalPath is a regular file holding exactly the bytes f's writer writes.
bool sameBytesAs(const PendingFile& f) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(fs::symlink_status(f.finalPath, ec))) return false;
  const fs::path temp = fs::temp_directory_path(ec) / tempPathFor(f.finalPath).filename();
  if (ec) return false;
  bool same = false;
  try {
    f.writer(temp);
    auto bytes = [](const fs::path& p) {
      std::ifstream in(p, std::ios::binary);
      return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    same = fs::file_size(temp, ec) == fs::file_size(f.finalPath, ec) && !ec && bytes(temp) == bytes(f.finalPath);
  } catch (const Error&) {
  }
  fs::remove(temp, ec);
  return same;
}

}  // namespace

std::vector<std::filesystem::path> writeSamples(const std::filesystem::path& outDir) {
  std::error_code ec;
  if (std::filesystem::exists(outDir, ec) && !std::filesystem::is_directory(outDir, ec))
    throw Error(ErrorCode::Usage, outDir.string(), "is a file, not a folder: give OUTDIR a folder");
  if (!std::filesystem::is_directory(outDir, ec) && !unwritableReason(outDir).empty())
    throw Error(ErrorCode::Usage, outDir.string(), unwritableReason(outDir) + " (OUTDIR)");
  // Every file is declared first: a file of the same name that irbake did not write there (its manifest
  // proves which) is refused before anything is written, so a user's furnace.gltf is never replaced.
  OutputGuard guard;
  guard.keepManifest(outDir);
  std::vector<std::unique_ptr<GltfDocument>> docs;  // the writers below read them
  std::vector<PendingFile> files;
  std::vector<std::filesystem::path> written;
  for (const auto& s : allSamples()) {
    const std::filesystem::path path = outDir / (s.name + ".gltf");
    docs.push_back(std::make_unique<GltfDocument>(gltfFromScene(s.scene)));
    for (PendingFile& f : docs.back()->files(path)) {
      // A file with exactly these bytes is a sample already (an older irbake wrote it without a manifest).
      const ExistingOutput existing = sameBytesAs(f) ? ExistingOutput::Replace : ExistingOutput::ReplaceOurs;
      guard.addOutput(f.finalPath, "the sample " + s.name, existing);
      files.push_back(std::move(f));
    }
    written.push_back(path);
  }
  std::filesystem::create_directories(outDir, ec);
  if (!std::filesystem::is_directory(outDir, ec))
    throw Error(ErrorCode::Io, outDir.string(), "cannot create folder: " + ec.message());
  guard.write(files);
  return written;
}

}  // namespace irbake::samples
