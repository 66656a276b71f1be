#include "common/command_line.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "common/error.h"

namespace irbake::cli {
namespace {

// Plain decimal integer, optional sign, nothing else; false when it does not fit in long long.
bool parseInteger(const std::string& text, long long& value) {
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  if (begin == end) return false;
  auto [ptr, ec] = std::from_chars(begin, end, value, 10);
  return ec == std::errc() && ptr == end;
}

bool parseFinite(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && std::isfinite(value);  // a NUL inside (a config's "1\u0000x") is not the end
}

std::string formatNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.10g", v);
  return buf;
}

std::string integerRange(long long lo, long long hi) {
  return "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
}

}  // namespace

// The shortest text that reads back as exactly v ("50", "0.1", "1e-300").
std::string canonicalNumber(double v) {
  char buf[64];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

bool parseWholeNumber(const std::string& text, long long& value) { return parseInteger(text, value); }

std::unique_ptr<CLI::App> makeApp(const std::string& name, const std::string& description) {
  auto app = std::make_unique<CLI::App>(description, name);
  app->footer(exitCodeHelp());
  app->get_formatter()->column_width(34);
  return app;
}

bool parse(CLI::App& app, const std::vector<std::string>& args) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    std::string help = app.help();
    if (help.empty() || help.back() != '\n') help += '\n';
    std::fputs(help.c_str(), stdout);
    return false;
  } catch (const CLI::CallForVersion& e) {
    std::printf("%s\n", e.what());
    return false;
  } catch (const CLI::ParseError& e) {
    throw Error(ErrorCode::Usage, "", std::string(e.what()) + " (see '" + app.get_name() + " --help')");
  }
  return true;
}

CLI::Validator integerIn(long long lo, long long hi) {
  return CLI::Validator(
      [lo, hi](std::string& text) -> std::string {
        long long v = 0;
        if (!parseInteger(text, v) || v < lo || v > hi)
          return "must be an integer in " + integerRange(lo, hi) + ", got '" + text + "'";
        text = std::to_string(v);
        return {};
      },
      "in " + integerRange(lo, hi));
}

CLI::Validator integerOrAuto(long long lo, long long hi, long long autoValue) {
  return CLI::Validator(
      [lo, hi, autoValue](std::string& text) -> std::string {
        if (text == "auto") {
          text = std::to_string(autoValue);
          return {};
        }
        long long v = 0;
        if (!parseInteger(text, v) || v < lo || v > hi)
          return "must be 'auto' or an integer in " + integerRange(lo, hi) + ", got '" + text + "'";
        text = std::to_string(v);
        return {};
      },
      "auto or " + integerRange(lo, hi));
}

CLI::Validator numberIn(double lo, double hi) {
  const std::string range = "[" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        double v = 0.0;
        if (!parseFinite(text, v) || v < lo || v > hi)
          return "must be a finite number in " + range + ", got '" + text + "'";
        text = canonicalNumber(v);
        return {};
      },
      "in " + range);
}

CLI::Validator numberOrAuto(double lo, double hi, double autoValue) {
  const std::string range = "[" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
  return CLI::Validator(
      [lo, hi, range, autoValue](std::string& text) -> std::string {
        if (text == "auto") {
          text = formatNumber(autoValue);
          return {};
        }
        double v = 0.0;
        if (!parseFinite(text, v) || v < lo || v > hi)
          return "must be 'auto' or a finite number in " + range + ", got '" + text + "'";
        text = canonicalNumber(v);
        return {};
      },
      "auto or " + range);
}

CLI::Validator numberList(size_t count) {
  return CLI::Validator(
      [count](std::string& text) -> std::string {
        std::stringstream ss(text);
        std::string item, canonical;
        size_t n = 0;
        while (std::getline(ss, item, ',')) {
          double v = 0.0;
          if (!parseFinite(item, v)) return "'" + item + "' is not a finite number";
          canonical += (n ? "," : "") + canonicalNumber(v);
          ++n;
        }
        if (n != count || (!text.empty() && text.back() == ','))
          return "needs " + std::to_string(count) + " comma-separated numbers, got '" + text + "'";
        text = canonical;
        return {};
      },
      std::to_string(count) + " numbers a,b,..");
}

std::vector<double> parseNumberList(const std::string& text) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(std::strtod(item.c_str(), nullptr));
  return out;
}

}  // namespace irbake::cli
