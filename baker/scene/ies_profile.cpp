// LM-63 text: an identifier line (absent before LM-63-1991), keyword lines, TILT=NONE | INCLUDE | <file>
// (INCLUDE: lamp-to-luminaire geometry, the number of tilt angles N, N angles, N factors), then numbers separated
// by blanks or commas over any number of lines: lamps, lumens per lamp, candela multiplier, vertical and
// horizontal angle counts, photometric type (1 C, 2 B, 3 A), units, width, length, height; ballast factor,
// ballast-lamp factor (future use), input watts; the vertical angles, the horizontal angles, and the candela
// values, one horizontal angle's vertical sweep after another. Tilt factors are not applied (EXT_lights_ies
// leaves them optional).
#include "scene/ies_profile.h"

#include <algorithm>
#include <cmath>
#include <cctype>
#include <cstdlib>
#include <utility>

#include "common/error.h"

namespace irbake {

namespace {

constexpr double kAngleTolerance = 1e-6;  // degrees: angles this close are the same
constexpr size_t kMaxAngles = 100000;     // per axis: far beyond any measured profile
constexpr size_t kMaxValues = 10000000;

struct Token {
  std::string text;
  int line = 0;
};

// Reads the numbers after the TILT line, each with its line for messages.
class NumberReader {
 public:
  NumberReader(const std::string& source, std::vector<Token> tokens, int lastLine)
      : source_(source), tokens_(std::move(tokens)), lastLine_(lastLine) {}

  [[noreturn]] void fail(int line, const std::string& message) const {
    throw Error(ErrorCode::InvalidData, source_, "IES profile, line " + std::to_string(line) + ": " + message);
  }

  double number(const std::string& what) {
    if (next_ >= tokens_.size()) fail(lastLine_, "the file ends before " + what);
    const Token& t = tokens_[next_++];
    line_ = t.line;
    char* end = nullptr;
    const double v = std::strtod(t.text.c_str(), &end);
    if (end != t.text.c_str() + t.text.size() || !std::isfinite(v))
      fail(t.line, "'" + t.text.substr(0, 40) + "' is not a number (" + what + ")");
    return v;
  }
  double nonNegative(const std::string& what) {
    const double v = number(what);
    if (v < 0.0) fail(line_, what + " is " + format(v) + ": must not be negative");
    return v;
  }
  size_t count(const std::string& what, size_t most) {
    const double v = number(what);
    if (!(v >= 1.0) || v != std::floor(v) || v > static_cast<double>(most))
      fail(line_, what + " is " + format(v) + ": must be a whole number from 1 to " + std::to_string(most));
    return static_cast<size_t>(v);
  }
  int line() const { return line_; }
  bool atEnd() const { return next_ >= tokens_.size(); }

  static std::string format(double v) {
    std::string s = std::to_string(v);
    while (s.size() > 1 && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
  }

 private:
  std::string source_;
  std::vector<Token> tokens_;
  size_t next_ = 0;
  int line_ = 0, lastLine_ = 0;
};

std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::string current;
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      lines.push_back(current);
      current.clear();
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    } else {
      current.push_back(c);
    }
  }
  if (!current.empty()) lines.push_back(current);
  return lines;
}

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

// The images of a listed horizontal angle under the profile's symmetry (first, last: the listed range).
std::vector<double> horizontalImages(double h, double first, double last, size_t count) {
  if (count == 1) return {0.0};
  if (std::abs(last - 90.0) < kAngleTolerance) return {h, 180.0 - h, 180.0 + h, 360.0 - h};
  if (std::abs(last - 180.0) < kAngleTolerance) return {h, 360.0 - h};
  if (std::abs(first - 90.0) < kAngleTolerance) return {h, 180.0 - h};  // LM-63-1995's 90–270
  return {h};
}

// Expands the listed horizontal angles to [0, 360] by the profile's symmetry (see ies_profile.h).
void expandHorizontal(IesProfile& p, const std::vector<double>& listed, const std::vector<double>& values) {
  const size_t nv = p.vertical.size();
  std::vector<std::pair<double, size_t>> images;
  for (size_t j = 0; j < listed.size(); ++j)
    for (double a : horizontalImages(listed[j], listed.front(), listed.back(), listed.size())) {
      a = std::fmod(a, 360.0);
      if (a < 0.0) a += 360.0;
      if (a > 360.0 - kAngleTolerance) a = 0.0;
      images.emplace_back(a, j);
    }
  std::stable_sort(images.begin(), images.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::vector<std::pair<double, size_t>> kept;
  for (const auto& image : images)
    if (kept.empty() || image.first - kept.back().first > kAngleTolerance) kept.push_back(image);
  kept.emplace_back(360.0, kept.front().second);
  for (const auto& [angle, column] : kept) {
    p.horizontal.push_back(angle);
    p.candela.insert(p.candela.end(), values.begin() + static_cast<std::ptrdiff_t>(column * nv),
                     values.begin() + static_cast<std::ptrdiff_t>((column + 1) * nv));
  }
}

// Everything before the numbers: the TILT line and, for TILT=INCLUDE, its data. Returns the index of the first
// line after the TILT line and whether tilt data follow.
size_t findTilt(const std::vector<std::string>& lines, const std::string& source, bool& include) {
  for (size_t i = 0; i < lines.size(); ++i) {
    const std::string line = trim(lines[i]);
    if (line.rfind("TILT", 0) != 0) continue;
    const size_t eq = line.find('=');
    if (eq == std::string::npos)
      throw Error(ErrorCode::InvalidData, source, "IES profile, line " + std::to_string(i + 1) + ": TILT without '='");
    include = trim(line.substr(eq + 1)) == "INCLUDE";
    return i + 1;
  }
  throw Error(ErrorCode::InvalidData, source,
              "IES profile, line " + std::to_string(lines.size()) + ": no TILT= line before the end of the file");
}

void checkAscending(NumberReader& r, const std::vector<double>& angles, const std::vector<int>& lines,
                    const std::string& what, double lo, double hi) {
  for (size_t i = 0; i < angles.size(); ++i) {
    if (angles[i] < lo - kAngleTolerance || angles[i] > hi + kAngleTolerance)
      r.fail(lines[i], what + " angle " + NumberReader::format(angles[i]) + " lies outside [" +
                           NumberReader::format(lo) + ", " + NumberReader::format(hi) + "]");
    if (i > 0 && !(angles[i] > angles[i - 1]))
      r.fail(lines[i], what + " angles must ascend (" + NumberReader::format(angles[i - 1]) + " then " +
                           NumberReader::format(angles[i]) + ")");
  }
}

void checkHorizontalRange(NumberReader& r, const std::vector<double>& h, int line) {
  auto is = [](double a, double b) { return std::abs(a - b) < kAngleTolerance; };
  const double first = h.front(), last = h.back();
  const bool ok = h.size() == 1 ? is(first, 0.0)
                                : (is(first, 0.0) && (is(last, 90.0) || is(last, 180.0) || is(last, 360.0))) ||
                                      (is(first, 90.0) && is(last, 270.0));
  if (!ok)
    r.fail(line, "horizontal angles from " + NumberReader::format(first) + " to " + NumberReader::format(last) +
                     ": type C needs 0 alone, 0–90, 0–180, 0–360 or 90–270");
}

}  // namespace

IesProfile parseIesProfile(const std::string& text, const std::string& source) {
  IesProfile p;
  p.source = source;
  p.text = text;
  const std::vector<std::string> lines = splitLines(text);
  bool include = false;
  const size_t first = findTilt(lines, source, include);
  std::vector<Token> tokens;
  for (size_t i = first; i < lines.size(); ++i) {
    std::string word;
    for (char c : lines[i] + " ") {
      if (std::isspace(static_cast<unsigned char>(c)) || c == ',') {
        if (!word.empty()) tokens.push_back({word, static_cast<int>(i + 1)});
        word.clear();
      } else {
        word.push_back(c);
      }
    }
  }
  NumberReader r(source, std::move(tokens), static_cast<int>(lines.size()));
  if (include) {
    r.number("the lamp-to-luminaire geometry");
    const size_t n = r.count("the number of tilt angles", kMaxAngles);
    for (size_t i = 0; i < 2 * n; ++i) r.number(i < n ? "a tilt angle" : "a tilt factor");
  }
  r.nonNegative("the number of lamps");
  r.number("the lumens per lamp");  // -1: absolute photometry
  const double multiplier = r.nonNegative("the candela multiplier");
  const size_t nv = r.count("the number of vertical angles", kMaxAngles);
  const size_t nh = r.count("the number of horizontal angles", kMaxAngles);
  const double type = r.number("the photometric type");
  if (type == 2.0 || type == 3.0)
    r.fail(r.line(), std::string("photometric type ") + (type == 2.0 ? "B" : "A") + " is not supported (type C only)");
  if (type != 1.0) r.fail(r.line(), "photometric type " + NumberReader::format(type) + " is not 1 (C), 2 (B) or 3 (A)");
  if (nv < 2) r.fail(r.line(), "a type C profile needs at least 2 vertical angles");
  if (nv * nh > kMaxValues) r.fail(r.line(), "too many candela values (" + std::to_string(nv * nh) + ")");
  r.number("the units type");
  for (const char* what : {"the width", "the length", "the height"}) r.number(what);
  const double ballast = r.nonNegative("the ballast factor");
  r.number("the ballast-lamp photometric factor");
  r.number("the input watts");
  std::vector<int> vLines(nv), hLines(nh);
  for (size_t i = 0; i < nv; ++i) {
    p.vertical.push_back(r.number("vertical angle " + std::to_string(i + 1) + " of " + std::to_string(nv)));
    vLines[i] = r.line();
  }
  std::vector<double> listed;
  for (size_t i = 0; i < nh; ++i) {
    listed.push_back(r.number("horizontal angle " + std::to_string(i + 1) + " of " + std::to_string(nh)));
    hLines[i] = r.line();
  }
  checkAscending(r, p.vertical, vLines, "vertical", 0.0, 180.0);
  checkAscending(r, listed, hLines, "horizontal", 0.0, 360.0);
  checkHorizontalRange(r, listed, hLines.back());
  std::vector<double> values(nv * nh);
  for (size_t i = 0; i < values.size(); ++i) {
    values[i] = r.nonNegative("candela value " + std::to_string(i + 1) + " of " + std::to_string(values.size())) *
                multiplier * ballast;
    p.maxCandela = std::max(p.maxCandela, values[i]);
  }
  expandHorizontal(p, listed, values);
  double sum = 0.0;
  for (size_t h = 0; h + 1 < p.horizontal.size(); ++h)
    for (size_t v = 0; v + 1 < p.vertical.size(); ++v) p.cellCdf.push_back(sum += p.cellIntegral(h, v));
  return p;
}

double IesProfile::candelaAt(double theta, double phi) const {
  if (!(theta >= vertical.front() - kAngleTolerance && theta <= vertical.back() + kAngleTolerance)) return 0.0;
  theta = std::clamp(theta, vertical.front(), vertical.back());
  phi = std::fmod(phi, 360.0);
  if (phi < 0.0) phi += 360.0;
  if (!(phi >= 0.0 && phi <= 360.0)) phi = 0.0;  // NaN
  const size_t v = std::min<size_t>(std::upper_bound(vertical.begin(), vertical.end(), theta) - vertical.begin(),
                                    vertical.size() - 1) - 1;
  const size_t h = std::min<size_t>(std::upper_bound(horizontal.begin(), horizontal.end(), phi) - horizontal.begin(),
                                    horizontal.size() - 1) - 1;
  const double s = (theta - vertical[v]) / (vertical[v + 1] - vertical[v]);
  const double t = (phi - horizontal[h]) / (horizontal[h + 1] - horizontal[h]);
  return (1.0 - t) * ((1.0 - s) * at(h, v) + s * at(h, v + 1)) + t * ((1.0 - s) * at(h + 1, v) + s * at(h + 1, v + 1));
}

std::vector<float> IesProfile::table(int rows, int columns) const {
  std::vector<float> out(static_cast<size_t>(rows) * static_cast<size_t>(columns));
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < columns; ++j)
      out[static_cast<size_t>(i) * static_cast<size_t>(columns) + static_cast<size_t>(j)] =
          static_cast<float>(candelaAt(180.0 * i / (rows - 1), 360.0 * j / (columns - 1)));
  return out;
}

double IesProfile::cellIntegral(size_t h, size_t v) const {
  constexpr double kRad = 3.14159265358979323846 / 180.0;
  const double t0 = vertical[v] * kRad, t1 = vertical[v + 1] * kRad, dt = t1 - t0;
  // ∫ sinθ dθ and ∫ θ sinθ dθ over [t0, t1]; the bilinear weights are linear in θ.
  const double s = std::cos(t0) - std::cos(t1);
  const double ts = (std::sin(t1) - t1 * std::cos(t1)) - (std::sin(t0) - t0 * std::cos(t0));
  const double a1 = (ts - t0 * s) / dt, a0 = (t1 * s - ts) / dt;
  const double halfPhi = 0.5 * (horizontal[h + 1] - horizontal[h]) * kRad;
  return halfPhi * (a0 * (at(h, v) + at(h + 1, v)) + a1 * (at(h, v + 1) + at(h + 1, v + 1)));
}

double IesProfile::integral() const { return cellCdf.empty() ? 0.0 : cellCdf.back(); }

}  // namespace irbake
