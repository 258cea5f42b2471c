#pragma once
// The library's version.

#include <groovetrace/export.hpp>

namespace groovetrace {

/// The library version string, e.g. "0.1.0" (the CMake project version).
GT_API const char* version();

}  // namespace groovetrace
