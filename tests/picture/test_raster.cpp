// The drawing primitives, the built-in font and the libpng encoder, read back through libpng.
#include <gtest/gtest.h>

#include <groovetrace/error.hpp>

#include "picture/font.hpp"
#include "picture/png.hpp"
#include "picture/raster.hpp"
#include "support/png_reader.hpp"

namespace groovetrace::picture {
namespace {

constexpr Rgb kRed{255, 0, 0}, kWhite{255, 255, 255};

TEST(Raster, LinesAndDiscsCoverTheirPixelsAndClipAtTheEdge) {
  Raster r(40, 30, {10, 20, 30});
  EXPECT_EQ(r.at(5, 5), (Rgb{10, 20, 30}));
  r.line({0.5, 10.5}, {39.5, 10.5}, 1.0, kRed);  // pixel centres of row 10
  for (int x = 0; x < 40; ++x) EXPECT_EQ(r.at(x, 10), kRed) << x;
  EXPECT_EQ(r.at(20, 8), (Rgb{10, 20, 30}));  // outside the stroke
  r.disc({20, 20}, 3.0, kWhite);
  EXPECT_EQ(r.at(19, 19), kWhite);
  EXPECT_EQ(r.at(20, 25), (Rgb{10, 20, 30}));
  // Shapes beyond the image, and non-finite ones, are clipped or skipped without a fault.
  r.line({-1e9, -1e9}, {1e9, 1e9}, 2.0, kWhite);
  r.disc({1e12, 5}, 4.0, kWhite);
  r.line({NAN, 0}, {5, 5}, 2.0, kRed);
  r.set(-1, 3, kRed);
  r.blend(40, 3, kRed, 1.0);
  EXPECT_EQ(r.at(0, 0), kWhite);  // on the diagonal
}

TEST(Raster, BlendAndMixWeighTheColours) {
  EXPECT_EQ(mix({0, 0, 0}, {200, 100, 50}, 0.5), (Rgb{100, 50, 25}));
  Raster r(2, 2, {0, 0, 0});
  r.blend(1, 1, {200, 200, 200}, 0.25);
  EXPECT_EQ(r.at(1, 1), (Rgb{50, 50, 50}));
  Raster big(6, 6, kWhite);
  big.paste(r, 5, 5);  // clipped: only r's pixel (0, 0) lands
  EXPECT_EQ(big.at(5, 5), (Rgb{0, 0, 0}));
}

TEST(Font, EveryPrintableGlyphButSpaceHasInk) {
  for (char c = 33; c < 127; ++c) {
    int ink = 0;
    for (std::uint8_t row : glyph(c)) ink += row != 0;
    EXPECT_GT(ink, 0) << c;
    for (std::uint8_t row : glyph(c)) EXPECT_LT(row, 1 << kGlyphWidth) << c;
  }
  for (std::uint8_t row : glyph(' ')) EXPECT_EQ(row, 0);
  EXPECT_EQ(glyph('\n'), glyph('?'));
  EXPECT_EQ(text_width("ab", 2), 2 * kGlyphAdvance * 2 - 2);
  EXPECT_EQ(text_width("", 3), 0);
}

TEST(Font, TextIsDrawnWhereAsked) {
  Raster r(60, 20, {0, 0, 0});
  draw_text(r, 2, 3, "H", 2, kWhite);
  // H: both stems on every capital row; its bar on row 3.
  EXPECT_EQ(r.at(2, 3), kWhite);
  EXPECT_EQ(r.at(2 + 4 * 2, 3 + 6 * 2), kWhite);
  EXPECT_EQ(r.at(2 + 2 * 2, 3 + 3 * 2), kWhite);
  EXPECT_EQ(r.at(2 + 2 * 2, 3), (Rgb{0, 0, 0}));
  draw_text(r, 50, 15, "clipped at the edge", 3, kWhite);  // no fault
}

TEST(Png, DecodesWithLibpngToTheSamePixels) {
  Raster r(7, 5, {1, 2, 3});
  r.set(6, 4, {250, 128, 7});
  r.set(0, 0, {9, 8, 7});
  const std::string bytes = encode_png(r);
  const test::DecodedPng png = test::decode_png(bytes);
  ASSERT_TRUE(png.ok);
  EXPECT_EQ(png.width, 7u);
  EXPECT_EQ(png.height, 5u);
  EXPECT_EQ(png.colour_type, PNG_COLOR_TYPE_RGB);
  EXPECT_EQ(png.bit_depth, 8);
  EXPECT_EQ(png.interlace, PNG_INTERLACE_NONE);
  ASSERT_EQ(png.rows.size(), 5u);
  for (int y = 0; y < 5; ++y) {
    ASSERT_EQ(png.rows[y].size(), 21u);
    for (int x = 0; x < 7; ++x) {
      const Rgb c = r.at(x, y);
      EXPECT_EQ((Rgb{png.rows[y][3 * x], png.rows[y][3 * x + 1], png.rows[y][3 * x + 2]}), c);
    }
  }
  EXPECT_EQ(encode_png(r), bytes);  // no time stamp: same image, same bytes
}

TEST(Png, AnEmptyRasterIsAnInternalError) {
  EXPECT_THROW(encode_png(Raster()), InternalError);
  EXPECT_THROW(Raster(0, 5), InternalError);
}

}  // namespace
}  // namespace groovetrace::picture
