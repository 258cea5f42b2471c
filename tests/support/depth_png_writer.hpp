#pragma once
// Writes PNGs through libpng for the depth PNG tests: 16-bit grey depth images as RealSense
// users store them, and the wrong kinds (8-bit, colour, interlaced) to check refusals.

#include <png.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

namespace groovetrace::test {

struct PngSpec {
  int width = 0, height = 0;
  int bit_depth = 16;                // 8 or 16
  int colour = PNG_COLOR_TYPE_GRAY;  // PNG_COLOR_TYPE_GRAY or PNG_COLOR_TYPE_RGB
  bool interlaced = false;           // Adam7
};

// libpng's errors longjmp back here; this frame holds nothing to clobber or destroy.
inline bool write_png_rows(png_structp png, png_infop info, FILE* f, const PngSpec& spec,
                           png_bytepp rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_init_io(png, f);
  png_set_IHDR(png, info, spec.width, spec.height, spec.bit_depth, spec.colour,
               spec.interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  return true;
}

// Writes `samples` (row-major, channels per pixel as `colour` says, each sample < 2^bit_depth)
// to `path`; false when libpng fails. Samples are stored big-endian, as PNG requires.
inline bool write_png(const std::filesystem::path& path, const PngSpec& spec,
                      const std::vector<std::uint16_t>& samples) {
  const int channels = spec.colour == PNG_COLOR_TYPE_RGB ? 3 : 1;
  const int bytes = spec.bit_depth / 8;
  const std::size_t stride = static_cast<std::size_t>(spec.width) * channels * bytes;
  std::vector<png_byte> raw(stride * spec.height);
  for (std::size_t i = 0; i < samples.size() && i * bytes < raw.size(); ++i) {
    if (bytes == 2) {
      raw[2 * i] = static_cast<png_byte>(samples[i] >> 8);
      raw[2 * i + 1] = static_cast<png_byte>(samples[i] & 0xff);
    } else {
      raw[i] = static_cast<png_byte>(samples[i]);
    }
  }
  std::vector<png_bytep> rows(spec.height);
  for (int r = 0; r < spec.height; ++r) rows[r] = raw.data() + r * stride;
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  const bool ok = png && info && write_png_rows(png, info, f, spec, rows.data());
  png_destroy_write_struct(&png, &info);
  return std::fclose(f) == 0 && ok;
}

// A 16-bit grey depth image.
inline bool write_depth_png(const std::filesystem::path& path, int width, int height,
                            const std::vector<std::uint16_t>& depth, bool interlaced = false) {
  return write_png(path, {width, height, 16, PNG_COLOR_TYPE_GRAY, interlaced}, depth);
}

}  // namespace groovetrace::test
