#pragma once
// PNG encoding of a Raster through libpng, into memory.

#include <string>

#include "picture/raster.hpp"

namespace groovetrace::picture {

/// The image as a PNG file's bytes: 8-bit RGB, not interlaced, no time stamp, so the same
/// image always gives the same bytes. Throws InternalError when libpng fails.
std::string encode_png(const Raster& image);

}  // namespace groovetrace::picture
