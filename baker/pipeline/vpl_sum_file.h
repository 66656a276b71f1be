// Partial VPL sums on disk: a shard's share for `irbake merge`, and the checkpoint a resumed bake starts
// from. Both are the exact sums of a contiguous range of VPL blocks plus what identifies the bake they
// belong to (hashes of the scene files and of the options, the seed, the backend used), so sums of
// different bakes are never added together. Written atomically (common/atomic_file.h).
#pragma once
#include "common/output_guard.h"
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pipeline/vpl_sums.h"

namespace irbake {

// What a file of VPL sums belongs to and holds. Two files belong to the same bake when sceneHash,
// optionsHash, seed, backend and blockCount agree.
struct VplSumHeader {
  std::string kind;            // "partial" (a shard's share) or "checkpoint" (a bake under way)
  std::string sceneHash;       // hashSceneFiles of the scene (hex)
  std::string optionsHash;     // hash of every option that changes the result (hex)
  nlohmann::json options;      // those options as name -> value (what a refusal names)
  uint32_t seed = 0;           // the walk seed
  std::string backend;         // the backend that evaluated the blocks (auto resolved)
  uint64_t blockCount = 0;     // VPL blocks of the whole bake
  uint64_t firstBlock = 0;     // the sums hold blocks [firstBlock, endBlock)
  uint64_t endBlock = 0;
  int shardIndex = 0;          // K of --shard K/N (1-based; 0: not a shard)
  int shardCount = 0;          // N
  nlohmann::json command;      // how to rebuild the bake at merge: scene path, arguments
  nlohmann::json backendCounts;  // the backend's counts over these blocks (report "gl")
  // Empty when `other` belongs to the same bake, else what differs ("scene", "options", "seed", ...).
  std::string mismatch(const VplSumHeader& other) const;
};

struct VplSumFile {
  VplSumHeader header;
  ExactVplSums sums;
};

// Writes header + sums to path atomically (only texels some block found valid carry sums).
void writeVplSumFile(const std::filesystem::path& path, const VplSumHeader& header, const ExactVplSums& sums,
                     const OutputGuard* guard = nullptr);
// Reads a file written by writeVplSumFile. Throws Error(Io) when unreadable, Error(Parse) when it is not
// such a file, is of another version, or fails its checksum (damaged, edited, truncated), naming the file.
VplSumFile readVplSumFile(const std::filesystem::path& path);

// XXH3-64 of the scene file and of every local file its buffers and images name (URIs decoded: a .gltf's
// .bin and textures, a GLB's external images), as 16 hex digits: a scene edited between shards, or between
// a checkpoint and its resume, is caught. Throws Error(Io) when the scene cannot be read.
std::string hashSceneFiles(const std::filesystem::path& scene);
// XXH3-64 of a string, as 16 hex digits.
std::string hashText(const std::string& text);

}  // namespace irbake
