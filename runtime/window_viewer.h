// Windowed irview (GLFW): fly camera, glTF camera jumps, view modes, F12 screenshots, frame time in the title.
#pragma once
#include "viewer_options.h"
#include "viewer_scene.h"

namespace irbake::view {

// Runs until Esc, window close, or options.frames frames; writes options.screenshot (if set) from the
// last frame's view before closing. Returns 0. Throws Error(Gl) when no window can be opened.
int runWindow(const ViewerScene& scene, const ViewerOptions& options);

}  // namespace irbake::view
