#include "pipeline/vpl_sum_file.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "common/atomic_file.h"
#include "common/error.h"

namespace irbake {

namespace {

// Version 2 (issue 15) adds the coefficient count (1: the map; 4: with the directional L1 pages) after the
// page count; version 1 files, written before, hold one coefficient and are read as such.
constexpr char kMagic[16] = "IRBAKE-VPLSUM-2";    // 15 characters + NUL
constexpr char kMagicV1[16] = "IRBAKE-VPLSUM-1";  // no coefficient count: one
constexpr char kEnd[8] = "VPLSEND";             // after the last page: a truncated file is refused

constexpr uint64_t kFnvOffset = 1469598103934665603ull, kFnvPrime = 1099511628211ull;
uint64_t fnv1a(const char* data, size_t size, uint64_t h = kFnvOffset) {
  for (size_t i = 0; i < size; ++i) h = (h ^ static_cast<unsigned char>(data[i])) * kFnvPrime;
  return h;
}
std::string hex(uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(v));
  return text;
}

bool readFile(const std::filesystem::path& path, std::string& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

template <class T>
void put(std::ostream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

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
  if (optionsHash != o.optionsHash) return "options";
  if (backend != o.backend) return "backend (" + backend + " vs " + o.backend + ")";
  if (blockCount != o.blockCount) return "VPL block count";
  return {};
}

void writeVplSumFile(const std::filesystem::path& path, const VplSumHeader& header, const ExactVplSums& sums) {
  const nlohmann::json h = {{"kind", header.kind},
                            {"sceneHash", header.sceneHash},
                            {"optionsHash", header.optionsHash},
                            {"seed", header.seed},
                            {"backend", header.backend},
                            {"blockCount", header.blockCount},
                            {"firstBlock", header.firstBlock},
                            {"endBlock", header.endBlock},
                            {"shardIndex", header.shardIndex},
                            {"shardCount", header.shardCount},
                            {"command", header.command},
                            {"backendCounts", header.backendCounts}};
  const std::string text = h.dump();
  writeAtomically(path, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    out.write(kMagic, sizeof kMagic);
    put(out, static_cast<uint64_t>(text.size()));
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    put(out, static_cast<uint64_t>(sums.pages.size()));
    put(out, static_cast<uint64_t>(sums.coefficients));
    // Per page: texel count, then per texel 0 (no sums), 1 (receiver, no block found it valid: zero sums
    // not written) or 2 (valid: its 3 · coefficients sums follow at the end of the page, in texel order).
    for (const ExactVplSums::Page& page : sums.pages) {
      put(out, static_cast<uint64_t>(page.slot.size()));
      std::vector<uint8_t> state(page.slot.size(), 0);
      for (size_t t = 0; t < state.size(); ++t)
        state[t] = page.slot[t] == ExactVplSums::kNoSum ? 0 : page.valid[t] ? 2 : 1;
      out.write(reinterpret_cast<const char*>(state.data()), static_cast<std::streamsize>(state.size()));
      for (size_t t = 0; t < state.size(); ++t)
        if (state[t] == 2)
          out.write(reinterpret_cast<const char*>(&page.values[sums.channels() * page.slot[t]]),
                    static_cast<std::streamsize>(sums.channels() * sizeof(ExactInt)));
    }
    out.write(kEnd, sizeof kEnd);
    out.close();
    if (!out) throw Error(ErrorCode::Io, path.string(), "cannot write the VPL sums");
  });
}

VplSumFile readVplSumFile(const std::filesystem::path& path) {
  std::string bytes;
  if (!readFile(path, bytes)) throw Error(ErrorCode::Io, path.string(), "cannot read the VPL sum file");
  Reader in{bytes, path};
  char magic[sizeof kMagic];
  in.take(magic, sizeof magic);
  const bool version1 = std::memcmp(magic, kMagicV1, sizeof kMagicV1) == 0;
  if (!version1 && std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw Error(ErrorCode::Parse, path.string(), "not an irbake VPL sum file (partial or checkpoint) of this version");
  const uint64_t textSize = in.get<uint64_t>();
  if (textSize > bytes.size()) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
  std::string text(textSize, '\0');
  in.take(text.data(), textSize);
  VplSumFile file;
  try {
    const nlohmann::json h = nlohmann::json::parse(text);
    VplSumHeader& hd = file.header;
    hd.kind = h.at("kind").get<std::string>();
    hd.sceneHash = h.at("sceneHash").get<std::string>();
    hd.optionsHash = h.at("optionsHash").get<std::string>();
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
  const uint64_t pageCount = in.get<uint64_t>();
  if (pageCount > bytes.size()) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
  const uint64_t coefficients = version1 ? 1 : in.get<uint64_t>();
  if (coefficients != 1 && coefficients != uint64_t(ExactVplSums::kMaxCoefficients))
    throw Error(ErrorCode::Parse, path.string(),
                "VPL sum file is damaged (" + std::to_string(coefficients) + " coefficients per texel)");
  file.sums.coefficients = static_cast<int>(coefficients);
  const size_t channels = file.sums.channels();
  for (uint64_t p = 0; p < pageCount; ++p) {
    const uint64_t texels = in.get<uint64_t>();
    if (texels > bytes.size()) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is truncated");
    std::vector<uint8_t> state(texels);
    in.take(state.data(), texels);
    std::vector<uint8_t> receivers(texels);
    for (size_t t = 0; t < texels; ++t) {
      if (state[t] > 2) throw Error(ErrorCode::Parse, path.string(), "VPL sum file is damaged (bad texel state)");
      receivers[t] = state[t] != 0;
    }
    ExactVplSums::Page page = std::move(ExactVplSums::zeros({receivers}, file.sums.coefficients).pages[0]);
    for (size_t t = 0; t < texels; ++t) {
      if (state[t] != 2) continue;
      in.take(&page.values[channels * page.slot[t]], channels * sizeof(ExactInt));
      page.valid[t] = 1;
    }
    file.sums.pages.push_back(std::move(page));
  }
  char end[sizeof kEnd];
  in.take(end, sizeof end);
  if (std::memcmp(end, kEnd, sizeof kEnd) != 0 || in.at != bytes.size())
    throw Error(ErrorCode::Parse, path.string(), "VPL sum file is damaged (bad end marker)");
  return file;
}

std::string hashText(const std::string& text) { return hex(fnv1a(text.data(), text.size())); }

std::string hashSceneFiles(const std::filesystem::path& scene) {
  std::string bytes;
  if (!readFile(scene, bytes)) throw Error(ErrorCode::Io, scene.string(), "cannot read the scene to hash it");
  uint64_t h = fnv1a(bytes.data(), bytes.size());
  // A .gltf names its buffers and images by URI: hash the local files too (data: URIs are in the bytes).
  const nlohmann::json doc = nlohmann::json::parse(bytes, nullptr, false);
  if (doc.is_object()) {
    for (const char* list : {"buffers", "images"}) {
      if (!doc.contains(list) || !doc[list].is_array()) continue;
      for (const auto& item : doc[list]) {
        if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
        const std::string uri = item["uri"].get<std::string>();
        if (uri.rfind("data:", 0) == 0) continue;
        std::string file;
        // A file that cannot be read hashes as its name: the loader has already refused it if it mattered.
        if (readFile(scene.parent_path() / uri, file)) h = fnv1a(file.data(), file.size(), h);
        else h = fnv1a(uri.data(), uri.size(), h);
      }
    }
  }
  return hex(h);
}

}  // namespace irbake
