// irbake unwrap (placeholder until its issue lands).
#include "app/commands.h"
#include "common/error.h"

namespace irbake::app {
int runUnwrap(const Args&) { throw Error(ErrorCode::Usage, "", "'irbake unwrap' is not built yet"); }
}  // namespace irbake::app
