// The irbake version: project(VERSION) in CMakeLists.txt plus the git commit seen at configure time.
#pragma once
#include <string>

namespace irbake {

const char* versionNumber();  // "0.4.0"
const char* gitCommit();      // short commit hash at configure time; "" outside a git checkout
std::string versionLine(const std::string& program);  // "irbake 0.4.0 (git 1a2b3c4d5e6f)"

}  // namespace irbake
