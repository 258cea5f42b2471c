#pragma once
// A built-in 5x7 bitmap font (with two rows below for descenders) for ASCII 32-126, enough
// for the overview's caption and labels without a font file or a font library.

#include <array>
#include <cstdint>
#include <string>

#include "picture/raster.hpp"

namespace groovetrace::picture {

constexpr int kGlyphWidth = 5, kGlyphHeight = 9;  ///< the cell; capitals use 7 rows
constexpr int kGlyphAdvance = kGlyphWidth + 1;    ///< pixels per character at scale 1

/// The rows of a glyph, top first; bit 4 of each row is the leftmost pixel. Characters outside
/// ASCII 32-126 get '?'.
const std::array<std::uint8_t, kGlyphHeight>& glyph(char c);

/// Width (pixels) of `text` drawn at `scale` (each font pixel a scale x scale block).
int text_width(const std::string& text, int scale);

/// Draws `text` with its top-left corner at pixel (x, y), clipped to the image.
void draw_text(Raster& image, int x, int y, const std::string& text, int scale, Rgb colour);

}  // namespace groovetrace::picture
