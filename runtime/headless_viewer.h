// Headless irview: renders through EGL (no display) and writes PNG/EXR screenshots or walkthrough frames.
#pragma once
#include <filesystem>
#include <vector>

#include "viewer_options.h"
#include "viewer_scene.h"

namespace irbake::view {

// Renders the start view (or the walkthrough frames) and writes them; returns the files written.
std::vector<std::filesystem::path> runHeadless(const ViewerScene& scene, const ViewerOptions& options);

}  // namespace irbake::view
