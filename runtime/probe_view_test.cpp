// irview's probe spheres on a real bake (the Cornell box sample, probes on, Embree, 512 paths): a matte white
// sphere of albedo 1 lit by the probes shows E(n)/π = shIrradiance(c(p), n) at each pixel's point p and normal n,
// c(p) the probes' field over the sphere (probeFieldOver: the blend at its centre and its gradient), plus the box's
// ceiling light, an exact emitter (lightmap/probe_emitter_field.h). The expected value is computed here from the exported glTF as `irbake probe`
// computes it (readLightProbes, interpolateProbes with visibility rays) and the normal from the camera ray's own
// intersection with the sphere (double precision), so the renderer's ray-cast, its SH and its interpolation
// (without visibility rays) are all checked. The centre sees its 8 probes, so both interpolations agree.
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/gltf_export.h"
#include "export/light_probes_export.h"
#include "glcontext/gl_context.h"
#include "pipeline/bake.h"
#include "probe_view.h"
#include "raytrace/ray_tracer.h"
#include "samples/sample_scenes.h"
#include "scene/gltf_loader.h"
#include "view_renderer.h"
#include "viewer_options.h"

namespace irbake::view {
namespace {

const glm::vec3 kCentre(0.2f, 0.4f, 0.2f);  // open air in the box: above the short block, beside the tall one
constexpr float kRadius = 0.05f;

std::filesystem::path outDir() {
  const char* dir = std::getenv("IRBAKE_BINARY_DIR");
  return std::filesystem::path(dir ? dir : ".") / "runtime_bake_test" / "probes";
}

// The Cornell box baked once with probes and exported (glTF + .bin + EXR pages).
const std::filesystem::path& bakedBox() {
  static const std::filesystem::path file = [] {
    BakeOptions o;
    o.backend = BackendKind::Embree;
    o.atlas.texelsPerUnit = 16.0f;
    o.walk.paths = 512;
    BakeResult baked = bake(samples::makeCornellBox(), o);
    EXPECT_GT(baked.probes.size(), 8u);
    ExportOptions ex;
    ex.output = outDir() / "cornell.gltf";
    ex.probes = &baked.probes;
    exportGltf(baked.scene, baked.maps, ex);
    return ex.output;
  }();
  return file;
}

// What `irbake probe FILE --at kCentre` blends: valid probes the point sees (visibility rays on the glTF); with
// the exact emitters' visibility blended the same way.
struct Reference : ProbeField {
  std::vector<ProbeEmitter> emitterLights;
  // What a white Lambert point at centre + offset with normal n shows: max(0, SH) + the exact emitters.
  glm::vec3 radiance(const glm::vec3& offset, const glm::vec3& n) const {
    return glm::max(shIrradiance(at(offset), n), glm::vec3(0.0f)) +
           exactEmitterLight(emitterLights, emitters.at(offset), kCentre + offset, n);
  }
};

Reference referenceField(const std::filesystem::path& file) {
  const LightProbeGrid grid = readLightProbes(file);
  LoadOptions load;
  load.decodeImages = false;
  const Scene scene = loadScene(file, load);
  const RayTracer rt(scene);
  const auto visible = [&](const glm::vec3& from, const glm::vec3& to) {
    const glm::vec3 d = to - from;
    const float r = glm::length(d);
    return !(r > 0.0f) || !rt.occluded(from, d / r, 0.0f, r);
  };
  Reference out;
  static_cast<ProbeField&>(out) = probeFieldOver(grid, kCentre, kRadius, visible);
  out.emitterLights = grid.emitters;
  return out;
}

// The sphere's normal seen through pixel (x, y) (row 0 at the top), from the camera's own matrices in double;
// false when the ray misses the sphere or passes within `rim` × radius of its silhouette (a pixel there mixes
// the sphere and what is behind it only in the coverage sense; the fragment is still exact, but one float ulp
// of the ray decides hit or miss).
bool sphereNormalAt(const ViewCamera& camera, int w, int h, int x, int y, double rim, glm::dvec3& n) {
  const glm::dmat4 inv = glm::inverse(glm::dmat4(camera.projection(static_cast<float>(w) / h) * camera.view()));
  const glm::dvec2 ndc((x + 0.5) / w * 2.0 - 1.0, 1.0 - (y + 0.5) / h * 2.0);
  const glm::dvec4 a = inv * glm::dvec4(ndc, -1.0, 1.0), b = inv * glm::dvec4(ndc, 0.5, 1.0);
  const glm::dvec3 eye = glm::dvec3(camera.position());
  const glm::dvec3 d = glm::normalize(glm::dvec3(b) / b.w - glm::dvec3(a) / a.w);
  const glm::dvec3 oc = eye - glm::dvec3(kCentre);
  const double along = glm::dot(oc, d);
  const glm::dvec3 closest = oc - along * d;
  const double r = kRadius, gap2 = r * r - glm::dot(closest, closest);
  if (gap2 < (2.0 * rim - rim * rim) * r * r) return false;  // the ray passes within rim·r of the silhouette
  const glm::dvec3 p = eye + (-along - std::sqrt(gap2)) * d;
  n = glm::normalize(p - glm::dvec3(kCentre));
  return true;
}

struct SphereCheck {
  int pixels = 0;
  double worst = 0.0;  // largest |pixel − expected| over channels, relative to the largest expected value
};

// Every sphere pixel against max(0, shIrradiance(c(p), n)) plus the exact emitters, p = centre + r n.
SphereCheck checkSphere(const std::vector<glm::vec4>& pixels, const ViewCamera& camera, int w, int h,
                        const Reference& field) {
  SphereCheck out;
  const glm::vec3 top = field.radiance(glm::vec3(0.0f), glm::vec3(0, 1, 0));
  const double scale = std::max({top.x, top.y, top.z, 1e-6f});
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      glm::dvec3 n;
      if (!sphereNormalAt(camera, w, h, x, y, 0.02, n)) continue;
      const glm::vec3 expected = field.radiance(kRadius * glm::vec3(n), glm::vec3(n));
      const glm::vec4& px = pixels[static_cast<size_t>(y) * w + x];
      for (int k = 0; k < 3; ++k) out.worst = std::max(out.worst, std::abs(px[k] - expected[k]) / scale);
      ++out.pixels;
    }
  return out;
}

TEST(ProbeView, SphereShowsTheProbesIrradianceAtEachPixelsNormal) {
  const std::filesystem::path file = bakedBox();
  const Reference reference = referenceField(file);
  ASSERT_EQ(reference.probes, 8) << "the centre should see its 8 probes";
  ASSERT_EQ(reference.emitterLights.size(), 1u) << "the box's ceiling light should be an exact emitter";
  const glm::vec3 mean = shAverage(reference.centre);
  ASSERT_GT(mean.x, 0.01f) << "the probes at the centre are dark";

  ViewerScene v = loadViewerScene(file);
  const ProbeSphere sphere = probeObject(readLightProbes(file), kCentre, kRadius, file);
  GlContext gl;
  ViewRenderer renderer(v);
  addProbeOverlay(renderer, {sphere});
  const int w = 65, h = 65;  // odd: the middle pixel's ray is the view axis
  // Three views: from the open front, from above (the middle pixel's normal is +Y, irbake probe's
  // --normal 0,1,0), and from below the centre.
  const glm::vec3 eyes[] = {kCentre + glm::vec3(0.05f, 0.02f, -0.3f), kCentre + glm::vec3(0.0f, 0.14f, 0.0f),
                            kCentre + glm::vec3(0.1f, -0.12f, -0.08f)};
  for (const glm::vec3& eye : eyes) {
    const ViewCamera camera = lookAt(eye, kCentre, 40.0f, v.scene.bounds());
    const RgbaImage img = renderer.render(camera, w, h, {});
    const SphereCheck check = checkSphere(img.pixels, camera, w, h, reference);
    EXPECT_GT(check.pixels, 300) << "the sphere should fill much of the view";
    // Float shading of the same sum in GLSL and C++, the normal from a float ray: 1e-3 of the brightest value.
    EXPECT_LT(check.worst, 1e-3) << "eye " << eye.x << "," << eye.y << "," << eye.z;
    RecordProperty("worstRelativeError", std::to_string(check.worst));
  }
  // From above, the middle pixel: the field at the sphere's top point, normal +Y.
  const ViewCamera above = lookAt(eyes[1], kCentre, 40.0f, v.scene.bounds());
  const glm::vec4 middle = renderer.render(above, w, h, {}).at(w / 2, h / 2);
  const glm::vec3 top = reference.radiance(glm::vec3(0.0f, kRadius, 0.0f), glm::vec3(0, 1, 0));
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(middle[k], top[k], 1e-3f * top[k]) << "channel " << k;
}

std::string runIrview(const std::string& args, const std::filesystem::path& log) {
  const std::string cmd = "\"" IRVIEW_EXE "\" " + args + " > \"" + log.string() + "\" 2>&1";
  const int status = std::system(cmd.c_str());
  std::ifstream in(log);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return (status == 0 ? "ok: " : "failed: ") + text;
}

// The command line another tool drives (Cycles comparisons): the EXR is linear radiance of the albedo-1 sphere.
TEST(ProbeView, IrviewProbeObjectScreenshotIsTheSpheresRadiance) {
  const std::filesystem::path file = bakedBox();
  const Reference reference = referenceField(file);
  ASSERT_EQ(reference.probes, 8);
  const std::filesystem::path exr = outDir() / "sphere.exr";
  std::filesystem::remove(exr);
  const glm::vec3 eye = kCentre + glm::vec3(0.05f, 0.02f, -0.3f);
  char args[512];
  std::snprintf(args, sizeof args,
                "\"%s\" --probe-object %g,%g,%g,%g --eye %g,%g,%g --target %g,%g,%g --fov 40 --width 65 --height 65 "
                "--screenshot \"%s\"",
                file.string().c_str(), kCentre.x, kCentre.y, kCentre.z, kRadius, eye.x, eye.y, eye.z, kCentre.x,
                kCentre.y, kCentre.z, exr.string().c_str());
  const std::string result = runIrview(args, outDir() / "sphere.log");
  ASSERT_EQ(result.rfind("ok: ", 0), 0u) << result;
  auto in = OIIO::ImageInput::open(exr.string());
  ASSERT_TRUE(in) << exr;
  const OIIO::ImageSpec spec = in->spec();
  ASSERT_EQ(spec.width, 65);
  std::vector<float> px(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, px.data()));
  std::vector<glm::vec4> pixels(static_cast<size_t>(spec.width) * spec.height);
  for (size_t i = 0; i < pixels.size(); ++i)
    for (int k = 0; k < 3; ++k) pixels[i][k] = px[i * spec.nchannels + k];
  const ViewCamera camera = lookAt(eye, kCentre, 40.0f, loadViewerScene(file).scene.bounds());
  const SphereCheck check = checkSphere(pixels, camera, spec.width, spec.height, reference);
  EXPECT_GT(check.pixels, 300);
  // The EXR's channels may be half floats (11-bit mantissa, 4.9e-4 relative): 1e-3 plus that.
  EXPECT_LT(check.worst, 1.5e-3);
}

// A corrupted probe extension (its sun level and exact emitters included) is refused naming the file and the problem, exit non-zero,
// no screenshot; so is a scene without probes.
TEST(ProbeView, IrviewRefusesABadProbeGrid) {
  const std::filesystem::path file = bakedBox();
  nlohmann::json doc;
  std::ifstream(file) >> doc;
  ASSERT_TRUE(doc["extensions"].contains("IRBAKE_light_probes"));
  auto write = [&](const nlohmann::json& j, const std::string& name) {
    const std::filesystem::path p = outDir() / name;  // beside the original: the same .bin and EXR pages
    std::ofstream(p) << j.dump();
    return p;
  };
  nlohmann::json longer = doc;
  longer["extensions"]["IRBAKE_light_probes"]["counts"][0] = longer["extensions"]["IRBAKE_light_probes"]["counts"][0].get<int>() + 1;
  nlohmann::json none = doc;
  none["extensions"].erase("IRBAKE_light_probes");
  nlohmann::json badSun = doc;  // a sun level of no subdivisions (its other fields absent)
  badSun["extensions"]["IRBAKE_light_probes"]["sun"] = {{"subdivisions", 0}};
  nlohmann::json darkSun = doc;  // a negative irradiance (checked before the accessors)
  darkSun["extensions"]["IRBAKE_light_probes"]["sun"] = {{"subdivisions", 4}, {"direction", {0, -1, 0}}, {"irradiance", {1, -1, 1}}};
  nlohmann::json badEmitter = doc;  // the ceiling light's triangle list pointing at the probes' validity (SCALAR)
  auto& emitter = badEmitter["extensions"]["IRBAKE_light_probes"]["emitters"][0];
  emitter["positions"] = badEmitter["extensions"]["IRBAKE_light_probes"]["valid"];
  const struct {
    std::filesystem::path file;
    std::string problem;
  } cases[] = {{write(longer, "bad_counts.gltf"), "the grid needs"}, {write(none, "no_probes.gltf"), "no IRBAKE_light_probes"},
               {write(badSun, "bad_sun.gltf"), "IRBAKE_light_probes.sun.subdivisions: needs a whole number from 1 to 16"},
               {write(darkSun, "dark_sun.gltf"), "IRBAKE_light_probes.sun.irradiance: negative"},
               {write(badEmitter, "bad_emitter.gltf"), "IRBAKE_light_probes.emitters[0].positions: accessor of componentType 5126 SCALAR"}};
  for (const auto& c : cases) {
    const std::filesystem::path png = outDir() / "refused.png";
    std::filesystem::remove(png);
    const std::string result = runIrview("\"" + c.file.string() + "\" --probe-object 0.2,0.4,0.2 --width 16 --height 16 --screenshot \"" +
                                             png.string() + "\"",
                                         outDir() / "refused.log");
    EXPECT_EQ(result.rfind("failed: ", 0), 0u) << result;
    EXPECT_NE(result.find(c.file.filename().string()), std::string::npos) << result;
    EXPECT_NE(result.find(c.problem), std::string::npos) << result;
    EXPECT_FALSE(std::filesystem::exists(png));
  }
}

}  // namespace
}  // namespace irbake::view
