// A small command-line parser shared by the subcommands: positionals, --flag, --opt VALUE / --opt=VALUE.
// Unknown options and bad values throw Error(Usage) naming the option.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace irbake {

class ArgParser {
 public:
  // valueOptions: options that take a value ("-o", "--vpls"); flags: options without one.
  ArgParser(const std::vector<std::string>& args, const std::set<std::string>& valueOptions,
            const std::set<std::string>& flags);
  const std::vector<std::string>& positionals() const { return positionals_; }
  bool flag(const std::string& name) const { return flags_.count(name) != 0; }
  std::optional<std::string> value(const std::string& name) const;
  std::string valueOr(const std::string& name, const std::string& fallback) const;
  int intOr(const std::string& name, int fallback) const;
  double doubleOr(const std::string& name, double fallback) const;
  // Comma-separated numbers ("0,-1,0,3.5"); throws when the count differs from expected.
  std::vector<double> numberList(const std::string& name, size_t expected) const;

 private:
  std::vector<std::string> positionals_;
  std::set<std::string> flags_;
  std::map<std::string, std::string> values_;
};

}  // namespace irbake
