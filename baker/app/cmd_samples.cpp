// irbake samples (placeholder until its issue lands).
#include "app/commands.h"
#include "common/error.h"

namespace irbake::app {
int runSamples(const Args&) { throw Error(ErrorCode::Usage, "", "'irbake samples' is not built yet"); }
}  // namespace irbake::app
