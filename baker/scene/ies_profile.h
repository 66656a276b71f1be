// IES LM-63 photometric profiles (LM-63-1986, -1991, -1995, -2002, -2019 text files) for EXT_lights_ies: the
// candela distribution of a luminaire over (vertical, horizontal) angles, photometric type C only.
//
// Type C: the vertical angle θ is measured from the nadir (the luminaire's aim, glTF's local −Z), the horizontal
// angle φ counter-clockwise seen from above, from local +X towards +Y. The horizontal angles a file lists end at
// 0 (the same in every plane), 90 (symmetric in each quadrant), 180 (symmetric about the 0–180° plane) or 360;
// an LM-63-1995 file may also list 90–270 (symmetric about that plane). The profile is kept expanded over
// φ ∈ [0, 360] by those symmetries, so one bilinear interpolation in (θ, φ) serves every case. Candela beyond the
// vertical angles the file lists is zero.
#pragma once
#include <string>
#include <vector>

namespace irbake {

struct IesProfile {
  std::string source;              // the file, or "glTF bufferView N", for messages
  std::string text;                // the file as read (written back on export)
  std::vector<double> vertical;    // θ in degrees, ascending, within [0, 180]
  std::vector<double> horizontal;  // φ in degrees, ascending, from 0 to 360
  // candela[h * vertical.size() + v]: the file's values × candela multiplier × ballast factor
  std::vector<double> candela;
  double maxCandela = 0.0;
  // Cumulative cellIntegral over the cells (h, v) in the order h · (vertical.size() − 1) + v: the walk's
  // emission picks a cell by its share of the power.
  std::vector<double> cellCdf;

  double at(size_t h, size_t v) const { return candela[h * vertical.size() + v]; }
  // Candela towards (θ, φ) in degrees (any φ; wrapped to [0, 360)), bilinear in the angles.
  double candelaAt(double thetaDegrees, double phiDegrees) const;
  // candelaAt on a regular grid for the GPU: rows × columns values, row i at θ = 180° · i / (rows − 1), column j at
  // φ = 360° · j / (columns − 1).
  std::vector<float> table(int rows, int columns) const;
  // ∫ candela dω over the sphere of the bilinear interpolant (exact, per cell), in candela·sr.
  double integral() const;
  // ∫ candela dω over cell (h, v): [horizontal[h], horizontal[h+1]] × [vertical[v], vertical[v+1]].
  double cellIntegral(size_t h, size_t v) const;
};

// Parses LM-63 text. Throws Error(InvalidData, source, "line N: ...") naming the line of a malformed profile and
// refuses photometric types A and B by name.
IesProfile parseIesProfile(const std::string& text, const std::string& source);

}  // namespace irbake
