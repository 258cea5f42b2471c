#include <groovetrace/version.hpp>

namespace groovetrace {

const char* version() { return GROOVETRACE_VERSION; }

}  // namespace groovetrace
