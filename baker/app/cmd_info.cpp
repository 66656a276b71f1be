// irbake info (placeholder until its issue lands).
#include "app/commands.h"
#include "common/error.h"

namespace irbake::app {
int runInfo(const Args&) { throw Error(ErrorCode::Usage, "", "'irbake info' is not built yet"); }
}  // namespace irbake::app
