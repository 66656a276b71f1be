#include "pipeline/vpl_sum_file.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "common/atomic_file.h"
#include "common/checksum.h"
#include "common/checksum.h"
#include "common/error.h"
#include "common/file_paths.h"
#include "scene/scene_files.h"

namespace irbake {

namespace {

// Version 3: an XXH3-64 checksum of every byte before it closes the file, so a flipped bit or an edited
// header is refused. Versions 1 and 2 had none and are refused as such.
constexpr char kMagic[16] = "IRBAKE-VPLSUM-3";   // 15 characters + NUL
constexpr char kMagicFamily[] = "IRBAKE-VPLSUM-";  // any version
constexpr char kEnd[8] = "VPLSEND";             // after the last page, before the checksum

bool readFile(const std::filesystem::path& path, std::string& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

// Writes bytes and checksums them on the way.
struct ChecksummedWriter {
  std::ofstream& out;
  Checksum64 sum;
  void write(const void* data, size_t size) {
    sum.add(data, size);
    out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  template <class T>
  void put(const T& v) {
    write(&v, sizeof v);
  }
};

// Reads from a byte string; every short read is the same error, naming the file.
struct Reader {
  const std::string& bytes;
  const std::filesystem::path& path;
  size_t at = 0;
  void take(void* to, size_t n) {
    if (bytes.size() - at < n) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
    std::memcpy(to, bytes.data() + at, n);
    at += n;
  }
  template <class T>
  T get() {
    T v;
    take(&v, sizeof v);
    return v;
  }
};

}  // namespace

std::string VplSumHeader::mismatch(const VplSumHeader& o) const {
  if (sceneHash != o.sceneHash) return "scene";
  if (seed != o.seed) return "seed";
  if (optionsHash != o.optionsHash) {
    // Name the options that differ: "options --seed (3 here, 0 there)".
    std::string which;
    nlohmann::json all = options.is_object() ? options : nlohmann::json::object();
    if (o.options.is_object()) all.update(o.options);
    auto valueIn = [](const nlohmann::json& set, const std::string& key) {
      if (!set.is_object() || !set.contains(key)) return std::string("default");
      return set[key].is_string() ? set[key].get<std::string>() : set[key].dump();
    };
    for (const auto& [key, unused] : all.items()) {
      const std::string mine = valueIn(options, key), theirs = valueIn(o.options, key);
      if (mine != theirs) which += (which.empty() ? " --" : ", --") + key + " (" + mine + " vs " + theirs + ")";
    }
    return "options" + which;
  }
  if (backend != o.backend) return "backend (" + backend + " vs " + o.backend + ")";
  if (blockCount != o.blockCount) return "VPL block count";
  return {};
}

void writeVplSumFile(const std::filesystem::path& path, const VplSumHeader& header, const ExactVplSums& sums,
                     const OutputGuard* guard) {
  const nlohmann::json h = {{"kind", header.kind},
                            {"sceneHash", header.sceneHash},
                            {"optionsHash", header.optionsHash},
                            {"options", header.options},
                            {"seed", header.seed},
                            {"backend", header.backend},
                            {"blockCount", header.blockCount},
                            {"firstBlock", header.firstBlock},
                            {"endBlock", header.endBlock},
                            {"shardIndex", header.shardIndex},
                            {"shardCount", header.shardCount},
                            {"command", header.command},
                            {"backendCounts", header.backendCounts}};
  const std::string text = h.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);  // paths need not be UTF-8
  const OutputGuard unguarded;  // callers without a command (tests) write through a guard that knows no input
  (guard ? *guard : unguarded).write(path, [&](const std::filesystem::path& temp) {
    std::ofstream file(temp, std::ios::binary);
    ChecksummedWriter out{file, {}};
    out.write(kMagic, sizeof kMagic);
    out.put(static_cast<uint64_t>(text.size()));
    out.write(text.data(), text.size());
    out.put(static_cast<uint64_t>(sums.pages.size()));
    out.put(static_cast<uint64_t>(sums.coefficients));
    // Per page: texel count, then per texel 0 (no sums), 1 (receiver, no block found it valid: zero sums
    // not written) or 2 (valid: its 3 · coefficients sums follow at the end of the page, in texel order).
    for (const ExactVplSums::Page& page : sums.pages) {
      out.put(static_cast<uint64_t>(page.slot.size()));
      std::vector<uint8_t> state(page.slot.size(), 0);
      for (size_t t = 0; t < state.size(); ++t)
        state[t] = page.slot[t] == ExactVplSums::kNoSum ? 0 : page.valid[t] ? 2 : 1;
      out.write(state.data(), state.size());
      for (size_t t = 0; t < state.size(); ++t)
        if (state[t] == 2) out.write(&page.values[sums.channels() * page.slot[t]], sums.channels() * sizeof(ExactInt));
    }
    out.write(kEnd, sizeof kEnd);
    const uint64_t checksum = out.sum.digest();
    file.write(reinterpret_cast<const char*>(&checksum), sizeof checksum);
    file.close();
    if (!file) throw Error(ErrorCode::Io, path.string(), "cannot write the VPL sums: " + writeFailureReason(temp, "write failed"));
  });
}

namespace {

// The header's JSON (Error(Parse) naming path when a field is missing or of the wrong type).
VplSumHeader parseHeader(const std::string& text, const std::filesystem::path& path) {
  VplSumHeader hd;
  try {
    const nlohmann::json h = nlohmann::json::parse(text);
    hd.kind = h.at("kind").get<std::string>();
    hd.sceneHash = h.at("sceneHash").get<std::string>();
    hd.optionsHash = h.at("optionsHash").get<std::string>();
    hd.options = h.value("options", nlohmann::json::object());
    hd.seed = h.at("seed").get<uint32_t>();
    hd.backend = h.at("backend").get<std::string>();
    hd.blockCount = h.at("blockCount").get<uint64_t>();
    hd.firstBlock = h.at("firstBlock").get<uint64_t>();
    hd.endBlock = h.at("endBlock").get<uint64_t>();
    hd.shardIndex = h.at("shardIndex").get<int>();
    hd.shardCount = h.at("shardCount").get<int>();
    hd.command = h.at("command");
    hd.backendCounts = h.at("backendCounts");
  } catch (const nlohmann::json::exception& e) {
    throw Error(ErrorCode::Parse, path.string(), std::string("bad VPL sum header: ") + e.what());
  }
  return hd;
}

// The pages after the header: per page its texel count, each texel's state and the sums of the valid ones.
void readPages(Reader& in, size_t fileSize, const std::filesystem::path& path, ExactVplSums& sums) {
  const uint64_t pageCount = in.get<uint64_t>();
  if (pageCount > fileSize) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
  const uint64_t coefficients = in.get<uint64_t>();
  if (coefficients != 1 && coefficients != uint64_t(ExactVplSums::kMaxCoefficients))
    throw Error(ErrorCode::Parse, path.string(),
                "VPL sum file is damaged (" + std::to_string(coefficients) + " coefficients per texel)");
  sums.coefficients = static_cast<int>(coefficients);
  const size_t channels = sums.channels();
  for (uint64_t p = 0; p < pageCount; ++p) {
    const uint64_t texels = in.get<uint64_t>();
    if (texels > fileSize) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
    std::vector<uint8_t> state(texels);
    in.take(state.data(), texels);
    std::vector<uint8_t> receivers(texels);
    for (size_t t = 0; t < texels; ++t) {
      if (state[t] > 2) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is damaged (bad texel state)");
      receivers[t] = state[t] != 0;
    }
    ExactVplSums::Page page = std::move(ExactVplSums::zeros({receivers}, sums.coefficients).pages[0]);
    for (size_t t = 0; t < texels; ++t) {
      if (state[t] != 2) continue;
      in.take(&page.values[channels * page.slot[t]], channels * sizeof(ExactInt));
      page.valid[t] = 1;
    }
    sums.pages.push_back(std::move(page));
  }
}

}  // namespace

VplSumFile readVplSumFile(const std::filesystem::path& path) {
  std::string bytes;
  if (!readFile(path, bytes)) throw Error(ErrorCode::Io, path.string(), "cannot read the VPL sum file");
  if (bytes.size() < sizeof kMagic || bytes.compare(0, sizeof kMagicFamily - 1, kMagicFamily) != 0)
    throw Error(ErrorCode::Parse, path.string(), "not an irbake VPL sum file (a partial of 'bake --shard' or a checkpoint)");
  if (std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw Error(ErrorCode::Parse, path.string(),
                "VPL sum file of another irbake version (" + std::string(bytes.data(), sizeof kMagic - 1) +
                    ", this one reads " + kMagic + "): bake it again");
  uint64_t stored = 0;
  if (bytes.size() < sizeof kMagic + sizeof stored) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  if (checksum64(bytes.data(), bytes.size() - sizeof stored) != stored)
    throw Error(ErrorCode::Parse, path.string(), "VPL sum file is damaged or truncated (checksum mismatch): bake it again");
  bytes.resize(bytes.size() - sizeof stored);
  Reader in{bytes, path};
  in.at = sizeof kMagic;
  const uint64_t textSize = in.get<uint64_t>();
  if (textSize > bytes.size()) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
  std::string text(textSize, '\0');
  in.take(text.data(), textSize);
  VplSumFile file;
  file.header = parseHeader(text, path);
  readPages(in, bytes.size(), path, file.sums);
  char end[sizeof kEnd];
  in.take(end, sizeof end);
  if (std::memcmp(end, kEnd, sizeof kEnd) != 0 || in.at != bytes.size())
    throw Error(ErrorCode::Parse, path.string(), "VPL sum file is damaged (bad end marker)");
  return file;
}

std::string hashText(const std::string& text) {
  Checksum64 h;
  h.add(text);
  return h.hex();
}

std::string hashSceneFiles(const std::filesystem::path& scene) {
  // What the loader reads: the scene's bytes and each local file its buffers and images name, by the
  // decoded URI (a .gltf's .bin and textures; a GLB's external images), each with its name.
  Checksum64 h;
  const bool gltf = hasExtension(scene, ".gltf") || hasExtension(scene, ".glb");
  std::vector<std::filesystem::path> files = {scene};
  if (gltf) files = sceneInputFiles(scene);
  for (size_t i = 0; i < files.size(); ++i) {
    std::string bytes;
    const std::string name = i == 0 ? std::string() : files[i].lexically_relative(scene.parent_path()).string();
    h.add(name);
    h.add("\0", 1);
    // A file that cannot be read hashes as its name: the loader has already refused it if it mattered.
    if (!readFile(files[i], bytes)) {
      if (i == 0) throw Error(ErrorCode::Io, scene.string(), "cannot read the scene to hash it");
      continue;
    }
    const uint64_t size = bytes.size();
    h.add(&size, sizeof size);
    h.add(bytes);
  }
  return h.hex();
}

}  // namespace irbake
