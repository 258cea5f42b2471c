#pragma once
// Reads PNG bytes back through libpng's full read API, independently of the encoder under
// test, so that tests see what any PNG viewer would.

#include <png.h>

#include <csetjmp>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace groovetrace::test {

struct DecodedPng {
  bool ok = false;
  std::uint32_t width = 0, height = 0;
  int colour_type = -1, bit_depth = 0, interlace = -1;
  std::vector<std::vector<std::uint8_t>> rows;  // as stored: 3 bytes per pixel for RGB 8
};

namespace detail {
struct Source {
  const std::string* bytes;
  std::size_t at = 0;
};
inline void read_bytes(png_structp png, png_bytep out, png_size_t n) {
  auto* src = static_cast<Source*>(png_get_io_ptr(png));
  if (src->at + n > src->bytes->size()) png_error(png, "truncated");
  std::memcpy(out, src->bytes->data() + src->at, n);
  src->at += n;
}
// setjmp lives here, in a frame without objects that need destructors.
inline bool read_into(png_structp png, png_infop info, DecodedPng& out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  out.width = png_get_image_width(png, info);
  out.height = png_get_image_height(png, info);
  out.colour_type = png_get_color_type(png, info);
  out.bit_depth = png_get_bit_depth(png, info);
  out.interlace = png_get_interlace_type(png, info);
  out.rows.assign(out.height, std::vector<std::uint8_t>(png_get_rowbytes(png, info)));
  for (auto& row : out.rows) png_read_row(png, row.data(), nullptr);
  png_read_end(png, nullptr);
  return true;
}
}  // namespace detail

inline DecodedPng decode_png(const std::string& bytes) {
  DecodedPng out;
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8))
    return out;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  detail::Source src{&bytes};
  png_set_read_fn(png, &src, &detail::read_bytes);
  out.ok = detail::read_into(png, info, out);
  png_destroy_read_struct(&png, &info, nullptr);
  return out;
}

}  // namespace groovetrace::test
