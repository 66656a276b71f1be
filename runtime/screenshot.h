// Screenshots: .exr = linear radiance (float RGB, no exposure, no tonemapping: comparable with a path
// tracer); .png = display image (× 2^exposure, clamped, sRGB-encoded, 8 bit). Written atomically.
#pragma once
#include <filesystem>

#include "common/output_guard.h"
#include "view_renderer.h"
#include "viewer_scene.h"

namespace irbake::view {

enum class ImageFormat { Png, Exr };

// From the extension (.png / .exr, any case); throws Error(Usage) naming the file otherwise.
ImageFormat imageFormatFor(const std::filesystem::path& path);

// Throws Error(NumericError) when a pixel is not finite, Error(Io) naming the file on write failure.
// Written through `guard` (common/output_guard.h): never onto one of the scene's files.
void writeScreenshot(const RgbaImage& image, const std::filesystem::path& path, float exposure, const OutputGuard& guard);

// The guard of irview's outputs: every file the scene was loaded from is an input.
OutputGuard viewerOutputGuard(const ViewerScene& scene);

// "walk.png", 7 → "walk_0007.png": the frames of a walkthrough.
std::filesystem::path frameName(const std::filesystem::path& path, int frame);

// sRGB transfer function (IEC 61966-2-1) of a linear value in [0,1].
float encodeSrgb(float linear);

}  // namespace irbake::view
