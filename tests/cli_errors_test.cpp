// `irbake info` on bad inputs: one line "irbake: error: <file>: <problem>", the exit code of the
// error class, no crash. Bad files are generated into the build folder from a valid triangle scene.
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <gtest/gtest.h>

#include "common/error.h"
#include "testing/gltf_builder.h"

using namespace irbake;
using json = nlohmann::json;

namespace {

struct RunResult {
  int exitCode = -1;
  std::string output;  // stdout and stderr together
};

RunResult runIrbake(const std::string& args) {
  std::string cmd = std::string("\"") + IRBAKE_EXE + "\" " + args + " 2>&1";
  RunResult r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf;
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), pipe)) > 0) r.output.append(buf.data(), n);
  int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;  // a crash (signal) is never a pass
  return r;
}

std::string quoted(const std::filesystem::path& p) {
  std::string q = "\"";
  q += p.string();
  q += '"';
  return q;
}

// A valid scene (one triangle, one point light) as <dir>/scene.gltf + scene.bin.
std::filesystem::path validScene(const std::string& name, const std::function<void(GltfDocument&)>& edit = {}) {
  auto dir = irbake::testing::testFolder("cli_" + name);
  GltfDocument doc = irbake::testing::meshDocument({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {0, 1, 2});
  doc.root["extensions"]["KHR_lights_punctual"]["lights"] = json::array({{{"type", "point"}, {"intensity", 5}}});
  doc.root["nodes"].push_back({{"translation", {0, 0, 1}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}});
  doc.root["scenes"][0]["nodes"] = {0, 1};
  if (edit) edit(doc);
  irbake::testing::writeDocument(doc, dir / "scene.gltf");
  return dir / "scene.gltf";
}

// Rewrites the JSON of a written .gltf.
void editJson(const std::filesystem::path& file, const std::function<void(json&)>& edit) {
  json j = json::parse(std::ifstream(file));
  edit(j);
  std::ofstream(file, std::ios::trunc) << j.dump();
}

// The error contract: exit code of the class, one line naming the file and containing `what`.
void expectError(const std::filesystem::path& file, ErrorCode code, const std::string& what) {
  RunResult r = runIrbake("info " + quoted(file));
  EXPECT_EQ(r.exitCode, exitCodeFor(code)) << r.output;
  EXPECT_NE(r.output.find("irbake: error: " + file.string() + ": "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(what), std::string::npos) << "expected '" << what << "' in: " << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << "not one line: " << r.output;
}

}  // namespace

TEST(CliErrors, MissingFile) {
  auto dir = irbake::testing::testFolder("cli_missing");
  expectError(dir / "nothing.gltf", ErrorCode::Io, "no such file");
}

TEST(CliErrors, DirectoryInsteadOfFile) {
  auto dir = irbake::testing::testFolder("cli_directory");
  std::filesystem::create_directories(dir / "folder.gltf");
  expectError(dir / "folder.gltf", ErrorCode::Io, "directory");
}

TEST(CliErrors, NotAGltfFile) {
  auto dir = irbake::testing::testFolder("cli_not_gltf");
  std::ofstream(dir / "notes.gltf") << "solid cube\nfacet normal 0 0 1\n";
  expectError(dir / "notes.gltf", ErrorCode::Parse, "not a glTF file");
}

TEST(CliErrors, JsonWithoutAsset) {
  auto dir = irbake::testing::testFolder("cli_no_asset");
  std::ofstream(dir / "x.gltf") << R"({"meshes": []})";
  expectError(dir / "x.gltf", ErrorCode::Parse, "no \"asset\"");
}

TEST(CliErrors, MalformedJson) {
  auto dir = irbake::testing::testFolder("cli_malformed");
  std::ofstream(dir / "broken.gltf") << R"({"asset": {"version": "2.0"}, "nodes": [ {"mesh": 0}, )";
  expectError(dir / "broken.gltf", ErrorCode::Parse, "malformed JSON");
}

TEST(CliErrors, BadGlbContainer) {
  auto dir = irbake::testing::testFolder("cli_bad_glb");
  std::ofstream out(dir / "bad.glb", std::ios::binary);
  const uint32_t header[5] = {0x46546C67u, 2u, 1000u, 8u, 0x4E4F534Au};  // claims 1000 bytes
  out.write(reinterpret_cast<const char*>(header), sizeof(header));
  out << "{}      ";
  out.close();
  expectError(dir / "bad.glb", ErrorCode::Parse, "bad GLB container");
}

TEST(CliErrors, MissingBuffer) {
  auto file = validScene("missing_buffer");
  std::filesystem::remove(file.parent_path() / "scene.bin");
  expectError(file, ErrorCode::Io, "missing buffer");
}

TEST(CliErrors, ShortBuffer) {
  auto file = validScene("short_buffer");
  std::filesystem::resize_file(file.parent_path() / "scene.bin", 10);
  expectError(file, ErrorCode::InvalidData, "short buffer");
}

TEST(CliErrors, AccessorOutOfBounds) {
  auto file = validScene("accessor_bounds");
  editJson(file, [](json& j) { j["accessors"][0]["byteOffset"] = 24; });  // 24 + 36 bytes > the 36-byte view
  expectError(file, ErrorCode::InvalidData, "out of bounds");
}

TEST(CliErrors, BufferViewOutOfBounds) {
  auto file = validScene("view_bounds");
  editJson(file, [](json& j) { j["bufferViews"][0]["byteOffset"] = 40; });  // past the 48-byte buffer end
  expectError(file, ErrorCode::InvalidData, "buffer view 0 is out of bounds");
}

TEST(CliErrors, IndexOutOfRange) {
  auto file = validScene("index_range", [](GltfDocument& doc) {
    doc.root["meshes"][0]["primitives"][0]["indices"] = doc.addIndices({0, 1, 7});
  });
  expectError(file, ErrorCode::InvalidData, "index 7 at position 2 is out of range (3 vertices)");
}

TEST(CliErrors, NanPosition) {
  auto file = validScene("nan_position");
  // POSITION is the first view at offset 0: make vertex 1's x a NaN in the .bin.
  std::fstream bin(file.parent_path() / "scene.bin", std::ios::in | std::ios::out | std::ios::binary);
  float nan = std::nanf("");
  bin.seekp(12);
  bin.write(reinterpret_cast<const char*>(&nan), 4);
  bin.close();
  expectError(file, ErrorCode::InvalidData, "NaN/Inf position at vertex 1");
}

TEST(CliErrors, RecursiveNodeGraph) {
  auto file = validScene("recursive");
  editJson(file, [](json& j) {
    j["nodes"][0]["children"] = {1};
    j["nodes"][1]["children"] = {0};
  });
  expectError(file, ErrorCode::InvalidData, "recursive node graph");
}

TEST(CliErrors, UriEscapingTheFolder) {
  auto file = validScene("uri_escape");
  // Put a real buffer outside the scene folder: it must be refused, not read.
  std::filesystem::copy_file(file.parent_path() / "scene.bin", file.parent_path().parent_path() / "outside.bin",
                             std::filesystem::copy_options::overwrite_existing);
  editJson(file, [](json& j) { j["buffers"][0]["uri"] = "../outside.bin"; });
  expectError(file, ErrorCode::InvalidData, "escapes the scene folder");
}

TEST(CliErrors, AbsoluteUri) {
  auto file = validScene("uri_absolute");
  editJson(file, [&](json& j) { j["buffers"][0]["uri"] = (file.parent_path() / "scene.bin").string(); });
  expectError(file, ErrorCode::InvalidData, "escapes the scene folder");
}

TEST(CliErrors, AbsurdDeclaredCount) {
  auto file = validScene("absurd_count");
  editJson(file, [](json& j) { j["accessors"][0]["count"] = 4000000000ull; });
  expectError(file, ErrorCode::InvalidData, "absurd size");
}

TEST(CliErrors, AbsurdBufferLength) {
  auto file = validScene("absurd_buffer");
  editJson(file, [](json& j) { j["buffers"][0]["byteLength"] = 1e15; });
  expectError(file, ErrorCode::InvalidData, "absurd size");
}

TEST(CliErrors, NoTriangles) {
  auto file = validScene("no_triangles");
  editJson(file, [](json& j) { j["meshes"][0]["primitives"][0]["mode"] = 0; });  // points
  expectError(file, ErrorCode::EmptyScene, "no triangles");
}

TEST(CliErrors, OnlyDegenerateTriangles) {
  auto file = validScene("degenerate_only", [](GltfDocument& doc) {
    doc.root["meshes"][0]["primitives"][0]["indices"] = doc.addIndices({0, 0, 1, 1, 2, 2});
  });
  expectError(file, ErrorCode::EmptyScene, "2 degenerate triangles dropped");
}

// Scale outside 1e-4 … 1e9 m: refused at load with the class's exit code, never an Embree abort or an all-zero map.
TEST(CliErrors, SceneScaleOutsideTheSupportedRange) {
  auto huge = validScene("scale_huge", [](GltfDocument& doc) { doc.root["nodes"][0]["scale"] = {1e10, 1e10, 1e10}; });
  expectError(huge, ErrorCode::InvalidData, "at a coordinate of 1e10 m, beyond the supported 1e9 m: rescale the scene");
  auto tiny = validScene("scale_tiny", [](GltfDocument& doc) { doc.root["nodes"][0]["scale"] = {1e-8, 1e-8, 1e-8}; });
  expectError(tiny, ErrorCode::InvalidData, "scene extent 1e-8 m (largest side of its bounding box) is outside the supported 1e-4 … 1e9 m");
}

TEST(CliErrors, NegativeLightColourAndUnsupportedRequiredExtension) {
  auto colour = validScene("negative_colour", [](GltfDocument& doc) {
    doc.root["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {-1, -1, -1};
  });
  expectError(colour, ErrorCode::InvalidData, "light 0 has a negative or non-finite colour (-1, -1, -1)");
  auto required = validScene("required_unknown", [](GltfDocument& doc) { doc.root["extensionsRequired"] = {"EXT_unknown_vendor_geometry"}; });
  expectError(required, ErrorCode::InvalidData, "requires extension EXT_unknown_vendor_geometry");
  // A supported extension whose data is broken: refused naming the extension and the primitive.
  auto draco = validScene("broken_draco", [](GltfDocument& doc) {
    doc.root["extensionsRequired"] = {"KHR_draco_mesh_compression"};
    doc.root["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"] = {{"bufferView", 99}, {"attributes", {{"POSITION", 0}}}};
  });
  expectError(draco, ErrorCode::InvalidData, "KHR_draco_mesh_compression: mesh 0 primitive 0: bufferView 99 is missing or out of range");
}

// 200,000 nested arrays in extras overflowed tinygltf's recursive parser (SIGSEGV). The depth scan
// refuses them first; brackets inside strings (with escaped quotes) do not count.
TEST(CliErrors, DeeplyNestedExtras) {
  auto file = validScene("deep_extras");
  const std::string deep = std::string(200000, '[') + std::string(200000, ']');
  std::string text;
  {
    std::ifstream in(file);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  // Shallow brackets inside a string, behind an escaped quote, are data, not nesting.
  const std::string inString = "\"extras\": {\"note\": \"\\\"" + std::string(100, '[') + "\"}, ";
  std::ofstream(file, std::ios::trunc) << "{" << inString << text.substr(1);
  RunResult ok = runIrbake("info " + quoted(file));
  EXPECT_EQ(ok.exitCode, 0) << ok.output;
  std::ofstream(file, std::ios::trunc) << "{\"extras\": " << deep << ", " << text.substr(1);
  expectError(file, ErrorCode::InvalidData, "JSON nests deeper than 64 arrays/objects");
}

TEST(CliErrors, DeeplyNestedGlbJsonChunk) {
  auto dir = irbake::testing::testFolder("cli_deep_glb");
  std::string json = "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + std::string(200000, '[') +
                     std::string(200000, ']') + "}";
  while (json.size() % 4) json += ' ';
  const uint32_t header[5] = {0x46546C67u, 2u, uint32_t(20 + json.size()), uint32_t(json.size()), 0x4E4F534Au};
  std::ofstream out(dir / "deep.glb", std::ios::binary);
  out.write(reinterpret_cast<const char*>(header), sizeof(header));
  out << json;
  out.close();
  expectError(dir / "deep.glb", ErrorCode::InvalidData, "JSON nests deeper than 64");
}

TEST(CliInfo, PrintsTheCornellBoxSummary) {
  auto dir = irbake::testing::testFolder("cli_info");
  RunResult w = runIrbake("samples " + quoted(dir) + " --quiet");
  ASSERT_EQ(w.exitCode, 0) << w.output;
  RunResult r = runIrbake("info " + quoted(dir / "cornell_box.gltf"));
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("triangles: 32 kept, 0 dropped"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("materials: 4"), std::string::npos);
  EXPECT_NE(r.output.find("emissive primitives: 1, total power W (0.729"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cameras: 1"), std::string::npos);
  EXPECT_NE(r.output.find("yfov 39.31"), std::string::npos);
}

TEST(CliInfo, GeometryOnlySceneIsNotAnErrorForInfo) {
  auto file = validScene("geometry_only", [](GltfDocument& doc) {
    doc.root.erase("extensions");
    doc.root["nodes"].erase(1);
    doc.root["scenes"][0]["nodes"] = {0};
  });
  RunResult r = runIrbake("info " + quoted(file));
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_NE(r.output.find("lights: 0"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("no light and no emitter"), std::string::npos) << r.output;
}

TEST(CliInfo, UsageErrorsExitWithTwo) {
  RunResult r = runIrbake("info");
  EXPECT_EQ(r.exitCode, exitCodeFor(ErrorCode::Usage));
  EXPECT_NE(r.output.find("exactly one SCENE"), std::string::npos) << r.output;
}

TEST(CliSamples, WritesEverySampleAsGltf) {
  auto dir = irbake::testing::testFolder("cli_samples");
  RunResult r = runIrbake("samples " + quoted(dir));
  ASSERT_EQ(r.exitCode, 0) << r.output;
  for (const char* name : {"cornell_box", "furnace", "point_over_plane", "quad_over_plane", "corner", "thin_wall", "textured_plane"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / (std::string(name) + ".gltf"))) << name;
    EXPECT_TRUE(std::filesystem::exists(dir / (std::string(name) + ".bin"))) << name;
  }
}

// --directional needs VPLs: with the reference backend it is refused before any work, nothing written.
TEST(CliErrors, DirectionalWithTheReferenceBackendIsAUsageError) {
  const auto scene = validScene("directional_reference");
  const auto out = scene.parent_path() / "out";
  RunResult r = runIrbake("bake " + quoted(scene) + " -o " + quoted(out) + " --backend reference --directional --quiet");
  EXPECT_EQ(r.exitCode, exitCodeFor(ErrorCode::Usage)) << r.output;
  EXPECT_NE(r.output.find("--directional needs a VPL backend"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(out / "lightmap_0.exr"));
}
