// Minimal leveled logging to stderr. Warnings are counted so reports can show them.
#pragma once
#include <string>

namespace irbake::log {

enum class Level { Debug, Info, Warn, Error, Quiet };

// The program name before every line ("irbake: warning: ..."); irview sets "irview".
void setProgram(const char* name);
void setLevel(Level level);
Level level();
void debug(const std::string& msg);
void info(const std::string& msg);
void warn(const std::string& msg);
void error(const std::string& msg);
int warningCount();

// The progress bar's line on stderr (common/progress.h draws through these). A log line first clears
// a bar that is on screen, so it always starts on a fresh line; the bar is drawn again on its next
// update.
void drawStatusLine(const std::string& text);  // "\r" + text, no newline
void endStatusLine();                          // ends a drawn bar's line with "\n"

}  // namespace irbake::log
