// irbake bake (placeholder until its issue lands).
#include "app/commands.h"
#include "common/error.h"

namespace irbake::app {
int runBake(const Args&) { throw Error(ErrorCode::Usage, "", "'irbake bake' is not built yet"); }
}  // namespace irbake::app
