// Minimal leveled logging to stderr. Warnings are counted so reports can show them.
#pragma once
#include <string>

namespace irbake::log {

enum class Level { Debug, Info, Warn, Error, Quiet };

void setLevel(Level level);
Level level();
void debug(const std::string& msg);
void info(const std::string& msg);
void warn(const std::string& msg);
void error(const std::string& msg);
int warningCount();

}  // namespace irbake::log
