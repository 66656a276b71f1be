// glTF accessor component types and element types, as the core specification numbers and names them.
#pragma once
#include <cstddef>
#include <string>

namespace irbake {

// Bytes of one component of `componentType` (5120 BYTE … 5126 FLOAT); 0 for a type glTF does not define.
inline size_t gltfComponentSize(int componentType) {
  switch (componentType) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
  }
}

// Components of one element of accessor type `type` ("SCALAR" … "MAT4"); 0 for an unknown type.
inline size_t gltfComponentCount(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}

}  // namespace irbake
