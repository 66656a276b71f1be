#include "testing/compressed_gltf.h"

#include <cstring>
#include <stdexcept>

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <meshoptimizer.h>

namespace irbake::testing {

namespace {

using json = nlohmann::json;

// The document around one primitive: the mesh on a node, a point light above it, one white material.
json documentAround(const json& primitive, const std::vector<glm::vec3>& positions) {
  glm::vec3 lo(positions.at(0)), hi(positions.at(0));
  for (const glm::vec3& p : positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  json light = {{"type", "point"}, {"intensity", 10.0}, {"color", {1.0, 1.0, 1.0}}};
  return {{"asset", {{"version", "2.0"}, {"generator", "irbake tests"}}},
          {"scene", 0},
          {"scenes", {{{"nodes", {0, 1}}}}},
          {"nodes", {{{"mesh", 0}}, {{"translation", {0.0, 0.0, 2.0}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}}},
          {"meshes", {{{"primitives", {primitive}}}}},
          {"materials", {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.8, 0.8, 1.0}}}}}}},
          {"extensions", {{"KHR_lights_punctual", {{"lights", {light}}}}}},
          {"accessors", {{{"componentType", 5125}, {"type", "SCALAR"}, {"count", 0}},
                         {{"componentType", 5126}, {"type", "VEC3"}, {"count", positions.size()},
                          {"min", {lo.x, lo.y, lo.z}}, {"max", {hi.x, hi.y, hi.z}}}}}};
}

void pad4(std::vector<uint8_t>& bin) {
  while (bin.size() % 4) bin.push_back(0);
}

void appendU32(std::vector<uint8_t>& out, uint32_t v) {
  uint8_t b[4];
  std::memcpy(b, &v, 4);
  out.insert(out.end(), b, b + 4);
}

}  // namespace

GlbParts meshoptParts(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices) {
  GlbParts parts;
  std::vector<uint8_t> ib(meshopt_encodeIndexBufferBound(indices.size(), positions.size()));
  ib.resize(meshopt_encodeIndexBuffer(ib.data(), ib.size(), indices.data(), indices.size()));
  std::vector<uint8_t> vb(meshopt_encodeVertexBufferBound(positions.size(), sizeof(glm::vec3)));
  vb.resize(meshopt_encodeVertexBuffer(vb.data(), vb.size(), positions.data(), positions.size(), sizeof(glm::vec3)));
  parts.bin = ib;
  pad4(parts.bin);
  const size_t vbOffset = parts.bin.size();
  parts.bin.insert(parts.bin.end(), vb.begin(), vb.end());
  const size_t indexBytes = indices.size() * 4, positionBytes = positions.size() * 12;
  json prim = {{"attributes", {{"POSITION", 1}}}, {"indices", 0}, {"material", 0}, {"mode", 4}};
  parts.json = documentAround(prim, positions);
  parts.json["accessors"][0]["count"] = indices.size();
  parts.json["accessors"][0]["bufferView"] = 0;
  parts.json["accessors"][1]["bufferView"] = 1;
  json meshopt0 = {{"buffer", 0}, {"byteOffset", 0}, {"byteLength", ib.size()}, {"byteStride", 4}, {"count", indices.size()}, {"mode", "TRIANGLES"}};
  json meshopt1 = {{"buffer", 0}, {"byteOffset", vbOffset}, {"byteLength", vb.size()}, {"byteStride", 12}, {"count", positions.size()}, {"mode", "ATTRIBUTES"}};
  parts.json["bufferViews"] = {
      {{"buffer", 1}, {"byteOffset", 0}, {"byteLength", indexBytes}, {"extensions", {{"EXT_meshopt_compression", meshopt0}}}},
      {{"buffer", 1}, {"byteOffset", indexBytes}, {"byteLength", positionBytes}, {"byteStride", 12}, {"extensions", {{"EXT_meshopt_compression", meshopt1}}}}};
  parts.json["buffers"] = {{{"byteLength", vbOffset + vb.size()}},
                           {{"byteLength", indexBytes + positionBytes}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
  parts.json["extensionsUsed"] = {"EXT_meshopt_compression", "KHR_lights_punctual"};
  parts.json["extensionsRequired"] = {"EXT_meshopt_compression"};
  return parts;
}

GlbParts dracoParts(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices) {
  draco::TriangleSoupMeshBuilder builder;
  const int faces = static_cast<int>(indices.size() / 3);
  builder.Start(faces);
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (int f = 0; f < faces; ++f)
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(f), &positions.at(indices[3 * f]), &positions.at(indices[3 * f + 1]),
                                      &positions.at(indices[3 * f + 2]));
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  draco::Encoder encoder;
  draco::EncoderBuffer stream;
  if (!mesh || !encoder.EncodeMeshToBuffer(*mesh, &stream).ok()) throw std::runtime_error("draco: cannot encode the test mesh");
  // The decoded point count is what the accessors declare: decode once to learn it.
  draco::DecoderBuffer in;
  in.Init(stream.data(), stream.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) throw std::runtime_error("draco: cannot decode the test mesh");
  const uint32_t points = decoded.value()->num_points(), id = decoded.value()->attribute(0)->unique_id();
  GlbParts parts;
  parts.bin.assign(stream.data(), stream.data() + stream.size());
  json prim = {{"attributes", {{"POSITION", 1}}}, {"indices", 0}, {"material", 0}, {"mode", 4},
               {"extensions", {{"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", id}}}}}}}};
  parts.json = documentAround(prim, positions);
  parts.json["accessors"][0]["count"] = decoded.value()->num_faces() * 3;
  parts.json["accessors"][1]["count"] = points;
  parts.json["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", stream.size()}}};
  parts.json["buffers"] = {{{"byteLength", stream.size()}}};
  parts.json["extensionsUsed"] = {"KHR_draco_mesh_compression", "KHR_lights_punctual"};
  parts.json["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  return parts;
}

std::vector<uint8_t> glbBytes(const GlbParts& parts) {
  std::string text = parts.json.dump();
  while (text.size() % 4) text.push_back(' ');
  std::vector<uint8_t> bin = parts.bin;
  pad4(bin);
  std::vector<uint8_t> out = {'g', 'l', 'T', 'F'};
  appendU32(out, 2);
  appendU32(out, static_cast<uint32_t>(12 + 8 + text.size() + (bin.empty() ? 0 : 8 + bin.size())));
  appendU32(out, static_cast<uint32_t>(text.size()));
  appendU32(out, 0x4E4F534Au);
  out.insert(out.end(), text.begin(), text.end());
  if (!bin.empty()) {
    appendU32(out, static_cast<uint32_t>(bin.size()));
    appendU32(out, 0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
  }
  return out;
}

}  // namespace irbake::testing
