# Finds every dependency once; modules link the imported targets below.
find_package(Threads REQUIRED)
find_package(embree 3 REQUIRED)
find_package(Eigen3 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(glm REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(CLI11 CONFIG REQUIRED)  # header-only command-line parsing (Debian libcli11-dev)
find_package(GTest REQUIRED)
find_package(benchmark REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
pkg_check_modules(EGL REQUIRED IMPORTED_TARGET egl)
pkg_check_modules(GLFW REQUIRED IMPORTED_TARGET glfw3)
pkg_check_modules(XXHASH REQUIRED IMPORTED_TARGET libxxhash)  # checksums of partials, checkpoints, scene files

# OpenMesh's CMake package has no version file: find it without a version and use OpenMeshCore.
find_package(OpenMesh REQUIRED)

# Decoders of compressed glTF geometry (KHR_draco_mesh_compression, EXT_meshopt_compression).
find_package(draco CONFIG REQUIRED)
find_package(meshoptimizer CONFIG REQUIRED)

# OpenImageIO's imported target may list an OpenCV include dir that does not exist on this machine:
# drop include dirs that are missing so CMake does not refuse the target.
find_package(OpenImageIO REQUIRED)
foreach(_oiio_target OpenImageIO::OpenImageIO OpenImageIO::OpenImageIO_Util)
  if(TARGET ${_oiio_target})
    get_target_property(_dirs ${_oiio_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(_dirs)
      set(_kept "")
      foreach(_d ${_dirs})
        if(EXISTS "${_d}" OR _d MATCHES "^\\$<")
          list(APPEND _kept "${_d}")
        endif()
      endforeach()
      set_target_properties(${_oiio_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_kept}")
    endif()
  endif()
endforeach()

# tinygltf ships in Debian as a shared library with a header; no CMake package.
find_path(TINYGLTF_INCLUDE_DIR tiny_gltf.h REQUIRED)
find_library(TINYGLTF_LIBRARY tinygltf REQUIRED)
add_library(tinygltf::tinygltf UNKNOWN IMPORTED)
set_target_properties(tinygltf::tinygltf PROPERTIES
  IMPORTED_LOCATION "${TINYGLTF_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${TINYGLTF_INCLUDE_DIR}")
