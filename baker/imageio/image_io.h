// Image files and encoded images through OpenImageIO, loaded on first use.
//
// OpenImageIO links about 260 shared libraries (OpenCV, GDAL, FFmpeg, DCMTK, ...). Linked into the
// commands, the dynamic loader spent a noticeable time at every start resolving their symbols, even for
// `irbake info` on a missing file. Only this small interface is linked; the OpenImageIO side is a
// plugin (libirbake_imageio_oiio.so, plugin/oiio_plugin.cpp) opened with dlopen the first time an
// image is decoded, encoded, read or written (docs/validation.md, "Start-up").
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace irbake::imageio {

// Decoded pixels, channels interleaved, row 0 at the top.
struct Pixels {
  int width = 0, height = 0, channels = 0;
  bool floatSource = false;    // the file holds float/half/double values (linear by convention)
  std::vector<uint8_t> u8;     // filled for 8-bit sources
  std::vector<float> f32;      // filled otherwise (integer formats normalised to [0,1])
  int page = 0;                // EXR attribute irbake:page (readFile only)
};

// What the plugin provides. Every function throws irbake::Error naming `name` (or the file).
struct Api {
  // format: an OpenImageIO format name ("png", "jpeg", "openexr", "hdr").
  Pixels (*decodeMemory)(const uint8_t* bytes, size_t size, const char* format, const std::string& name);
  // 8-bit RGBA pixels → PNG bytes.
  std::vector<uint8_t> (*encodePngMemory)(const uint8_t* rgba, int width, int height, const std::string& name);
  // Writes float (f32) or 8-bit (u8) pixels into file as format ("openexr" zip-compressed, or "png");
  // a non-negative page becomes the EXR attributes irbake:page and irbake:content. name: for errors.
  void (*writeFile)(const std::string& file, const char* format, const Pixels& pixels, int page, const std::string& name);
  // Reads any image file as float pixels.
  Pixels (*readFile)(const std::string& file);
};

// The plugin's functions; opens it on the first call. Throws Error(Io) when it cannot be loaded.
const Api& api();

}  // namespace irbake::imageio

// A plugin's entry point, the one symbol api() looks up: at global scope in the plugin's source, with its
// four functions (which may sit in an unnamed namespace).
#define IRBAKE_IMAGEIO_PLUGIN_ENTRY(decodeMemory, encodePngMemory, writeFile, readFile)                     \
  extern "C" __attribute__((visibility("default"))) const irbake::imageio::Api* irbake_imageio_api() {     \
    static const irbake::imageio::Api api{decodeMemory, encodePngMemory, writeFile, readFile};             \
    return &api;                                                                                          \
  }
