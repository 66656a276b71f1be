#include "common/args.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "common/error.h"

namespace irbake {

ArgParser::ArgParser(const std::vector<std::string>& args, const std::set<std::string>& valueOptions,
                     const std::set<std::string>& flags) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() > 1 && a[0] == '-' && !(a.size() > 1 && (std::isdigit(static_cast<unsigned char>(a[1])) || a[1] == '.'))) {
      std::string name = a, val;
      bool hasEq = false;
      if (auto eq = a.find('='); eq != std::string::npos) {
        name = a.substr(0, eq);
        val = a.substr(eq + 1);
        hasEq = true;
      }
      if (flags.count(name)) {
        if (hasEq) throw Error(ErrorCode::Usage, "", "option " + name + " takes no value");
        flags_.insert(name);
      } else if (valueOptions.count(name)) {
        if (!hasEq) {
          if (i + 1 >= args.size()) throw Error(ErrorCode::Usage, "", "option " + name + " needs a value");
          val = args[++i];
        }
        values_[name] = val;
      } else {
        throw Error(ErrorCode::Usage, "", "unknown option " + name);
      }
    } else {
      positionals_.push_back(a);
    }
  }
}

std::optional<std::string> ArgParser::value(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return std::nullopt;
  return it->second;
}

std::string ArgParser::valueOr(const std::string& name, const std::string& fallback) const {
  return value(name).value_or(fallback);
}

int ArgParser::intOr(const std::string& name, int fallback) const {
  auto v = value(name);
  if (!v) return fallback;
  char* end = nullptr;
  long r = std::strtol(v->c_str(), &end, 10);
  if (v->empty() || *end != 0) throw Error(ErrorCode::Usage, "", "option " + name + " needs an integer, got '" + *v + "'");
  return static_cast<int>(r);
}

double ArgParser::doubleOr(const std::string& name, double fallback) const {
  auto v = value(name);
  if (!v) return fallback;
  char* end = nullptr;
  double r = std::strtod(v->c_str(), &end);
  if (v->empty() || *end != 0 || !std::isfinite(r))
    throw Error(ErrorCode::Usage, "", "option " + name + " needs a finite number, got '" + *v + "'");
  return r;
}

std::vector<double> ArgParser::numberList(const std::string& name, size_t expected) const {
  auto v = value(name);
  if (!v) return {};
  std::vector<double> out;
  std::stringstream ss(*v);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    double r = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != 0 || !std::isfinite(r))
      throw Error(ErrorCode::Usage, "", "option " + name + ": '" + item + "' is not a finite number");
    out.push_back(r);
  }
  if (out.size() != expected)
    throw Error(ErrorCode::Usage, "", "option " + name + " needs " + std::to_string(expected) + " comma-separated numbers");
  return out;
}

}  // namespace irbake
