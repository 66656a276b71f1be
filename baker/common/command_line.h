// Command-line parsing for irbake's subcommands and irview, on CLI11: typed options with range
// checks that never wrap, generated --help with the exit codes, and every parse error turned into
// Error(Usage) so the commands print one line and exit 2.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace irbake::cli {

// An app for one command ("irbake bake"): help footer lists the exit codes.
std::unique_ptr<CLI::App> makeApp(const std::string& name, const std::string& description);

// Parses args (without the program and command names). Returns false when --help (or a version
// flag) was asked for and printed to stdout (the command then exits 0). Throws Error(Usage) with CLI11's message and a hint
// to the command's --help for any other problem.
bool parse(CLI::App& app, const std::vector<std::string>& args);

// Validators, to be added with ->transform() (->check() would drop their rewrite). Each checks the
// text before conversion and rewrites it to plain decimal (numbers to the shortest text that reads back
// the same double, so "100.0" and "100" are one value), so CLI11's own conversion (which reads "010" as
// octal) never sees anything but a checked number.
CLI::Validator integerIn(long long lo, long long hi);                      // an integer in [lo, hi]
CLI::Validator integerOrAuto(long long lo, long long hi, long long autoValue);  // or "auto" → autoValue
CLI::Validator numberIn(double lo, double hi);                             // a finite number in [lo, hi]
CLI::Validator numberOrAuto(double lo, double hi, double autoValue);      // or "auto" → autoValue
CLI::Validator numberList(size_t count);                                  // "x,y,z": count finite numbers

// A plain decimal integer (optional '+'), nothing else; false when it is not one or does not fit.
bool parseWholeNumber(const std::string& text, long long& value);

// The numbers of a list that numberList(count) accepted.
std::vector<double> parseNumberList(const std::string& text);

// The shortest text that reads back as exactly v ("50", "0.1", "1e-300").
std::string canonicalNumber(double v);

}  // namespace irbake::cli
