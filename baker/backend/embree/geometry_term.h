// Moved to transport/geometry_term.h (the maths both VPL backends share sits below them); this forwarding header
// stays until gl, interleave, pipeline and bench include the new path.
#pragma once
#include "transport/geometry_term.h"
