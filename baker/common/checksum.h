// 64-bit checksums (XXH3, libxxhash) of files irbake writes and reads back, and of the scene's files.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace irbake {

// Streaming XXH3-64: feed bytes in any pieces, the digest is that of their concatenation.
class Checksum64 {
 public:
  Checksum64();
  ~Checksum64();
  Checksum64(const Checksum64&) = delete;
  Checksum64& operator=(const Checksum64&) = delete;
  void add(const void* data, size_t size);
  void add(const std::string& bytes) { add(bytes.data(), bytes.size()); }
  uint64_t digest() const;
  std::string hex() const;  // 16 hex digits

 private:
  void* state_;
};

uint64_t checksum64(const void* data, size_t size);

}  // namespace irbake
