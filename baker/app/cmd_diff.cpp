// irbake diff (placeholder until its issue lands).
#include "app/commands.h"
#include "common/error.h"

namespace irbake::app {
int runDiff(const Args&) { throw Error(ErrorCode::Usage, "", "'irbake diff' is not built yet"); }
}  // namespace irbake::app
