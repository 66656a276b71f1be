// Constants and small helpers every stage uses, defined once so that a formula reads the same everywhere.
#pragma once
#include <glm/glm.hpp>

namespace irbake {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInvPi = 1.0 / kPi;
constexpr float kPiF = static_cast<float>(kPi);
constexpr float kInvPiF = static_cast<float>(kInvPi);
// 1/π² in float: a map value (irradiance / π) of a VPL is Φ · G / π² (backend formulas, transport/geometry_term.h).
constexpr float kInvPi2F = 1.0f / (kPiF * kPiF);

// Mean of the three channels: the scalar that power splits, stopping tests and figures compare. The float
// channels are summed in float and divided in double, as the loops that wrote it out by hand did.
inline double channelMean(const glm::vec3& c) { return (c.x + c.y + c.z) / 3.0; }
inline double channelMean(const glm::dvec3& c) { return (c.x + c.y + c.z) / 3.0; }

}  // namespace irbake
