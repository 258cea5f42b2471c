// A 16-bit grey depth PNG decoded through libpng and deprojected with its intrinsics. libpng
// reports errors by longjmp to the setjmp in read_rows: no C++ exception crosses its C frames,
// and the frame that calls setjmp holds no object with a destructor.
#include "io/depth_png.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <csetjmp>
#include <cstring>
#include <filesystem>
#include <groovetrace/error.hpp>
#include <string>
#include <tuple>
#include <utility>

#include "io/text.hpp"

namespace groovetrace::io {
namespace {

// Deflate expands at most 1032 times (its densest code, 258-byte matches in about 2 bits):
// image data beyond 1032 times the file's size cannot be in the file.
constexpr std::uint64_t kMaxInflation = 1032;

struct Source {
  const std::string& bytes;
  std::size_t pos = 0;
  std::string error;  // libpng's message, when it failed
};

void on_error(png_structp png, png_const_charp message) {
  static_cast<Source*>(png_get_error_ptr(png))->error = message ? message : "unknown error";
  png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}  // a bad ancillary chunk changes no depth

void on_read(png_structp png, png_bytep data, png_size_t length) {
  auto* src = static_cast<Source*>(png_get_io_ptr(png));
  if (src->bytes.size() - src->pos < length) png_error(png, "the file ends early");
  std::memcpy(data, src->bytes.data() + src->pos, length);
  src->pos += length;
}

std::uint32_t be32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t k = 0; k < 4; ++k) v = (v << 8) | static_cast<unsigned char>(b[at + k]);
  return v;
}

// The header's claims, checked before libpng allocates anything: a PNG starts with its
// signature and the IHDR chunk (width and height at bytes 16-23, bit depth and colour type
// at 24-25).
void check_header(const std::string& b) {
  if (b.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(b.data()), 0, 8) != 0) {
    reject("is not a PNG file");
  }
  if (b.size() < 33 || b.compare(12, 4, "IHDR") != 0) reject("has no PNG header (IHDR)");
  const std::uint32_t w = be32(b, 16), h = be32(b, 20);
  const int depth = static_cast<unsigned char>(b[24]), colour = static_cast<unsigned char>(b[25]);
  if (depth != 16 || colour != PNG_COLOR_TYPE_GRAY) {
    const char* what = colour == PNG_COLOR_TYPE_GRAY ? "grey" : "colour";
    reject(std::string(depth == 8 ? "is an " : "is a ") + std::to_string(depth) + "-bit " + what +
           " PNG, not a 16-bit grey depth image (a colourized depth picture, such as "
           "rs-convert's, holds no depth)");
  }
  if (w == 0 || h == 0 || w > kMaxDepthSide || h > kMaxDepthSide) {
    reject("has a header claiming " + std::to_string(w) + "x" + std::to_string(h) +
           " pixels (at most " + std::to_string(kMaxDepthSide) + " per side)");
  }
  const std::uint64_t raw = (2ull * w + 1) * h;  // a filter byte per row
  if (raw > kMaxInflation * b.size()) {
    reject("has a header claiming " + std::to_string(w) + "x" + std::to_string(h) +
           " pixels, more than its " + std::to_string(b.size()) + " bytes can hold");
  }
}

// Reads every row into `rows` (height * 2 * width bytes, big-endian samples); false when
// libpng reported an error (truncated or corrupt data).
bool read_rows(png_structp png, png_infop info, std::vector<png_bytep>& row_pointers) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_user_limits(png, kMaxDepthSide, kMaxDepthSide);
  png_read_info(png, info);
  if (png_get_bit_depth(png, info) != 16 || png_get_color_type(png, info) != PNG_COLOR_TYPE_GRAY) {
    png_error(png, "not a 16-bit grey image");
  }
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  png_read_image(png, row_pointers.data());
  png_read_end(png, nullptr);  // the chunks after the image, up to IEND: a cut file fails here
  return true;
}

}  // namespace

std::pair<std::uint32_t, std::uint32_t> depth_png_size(const std::string& bytes,
                                                       const std::string& path) {
  try {
    check_header(bytes);
  } catch (const Rejected& r) {
    throw InputError(shown(path) + " " + r.what);  // every reason above starts with a verb
  }
  return {be32(bytes, 16), be32(bytes, 20)};
}

DepthImage decode_depth_png(const std::string& bytes, const std::string& path) {
  DepthImage image;
  std::tie(image.width, image.height) = depth_png_size(bytes, path);
  // libpng writes the rows' big-endian samples straight into the depth array; they are put
  // in host order afterwards, in place (one buffer: 2 bytes per pixel).
  image.depth.resize(static_cast<std::size_t>(image.width) * image.height);
  auto* raw = reinterpret_cast<png_bytep>(image.depth.data());
  const std::size_t stride = 2 * static_cast<std::size_t>(image.width);
  std::vector<png_bytep> rows(image.height);
  for (std::size_t r = 0; r < rows.size(); ++r) rows[r] = raw + r * stride;

  Source src{bytes, 0, ""};
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &src, &on_error, &on_warning);
  if (!png) throw InternalError("png: cannot create the libpng reader");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_read_struct(&png, nullptr, nullptr);
    throw InternalError("png: cannot create the libpng info");
  }
  png_set_read_fn(png, &src, &on_read);
  const bool ok = read_rows(png, info, rows);
  png_destroy_read_struct(&png, &info, nullptr);
  if (!ok) throw InputError(shown(path) + ": truncated or corrupt PNG data (" + src.error + ")");
  for (std::size_t i = 0; i < image.depth.size(); ++i) {
    image.depth[i] = static_cast<std::uint16_t>((raw[2 * i] << 8) | raw[2 * i + 1]);
  }
  return image;
}

Cloud depth_to_cloud(const DepthImage& image, const DepthIntrinsics& k) {
  Cloud cloud;
  cloud.width = image.width;
  cloud.height = image.height;
  cloud.resize(image.depth.size());
  for (std::uint32_t row = 0; row < image.height; ++row) {
    for (std::uint32_t col = 0; col < image.width; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * image.width + col;
      const std::uint16_t d = image.depth[i];
      if (d == 0) {
        cloud.x[i] = cloud.y[i] = cloud.z[i] = NAN;
        continue;
      }
      const double z = d * k.depth_scale;
      cloud.x[i] = static_cast<float>((col - k.ppx) * z / k.fx);
      cloud.y[i] = static_cast<float>((row - k.ppy) * z / k.fy);
      cloud.z[i] = static_cast<float>(z);
    }
  }
  return cloud;
}

namespace {

void check_points(const Cloud& cloud, const std::string& path, std::size_t min_valid) {
  std::size_t beyond = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    beyond += cloud.valid(i) && beyond_max_coordinate(cloud.x[i], cloud.y[i], cloud.z[i]);
  }
  if (beyond > 0) {
    throw InputError(shown(path) + " has " + count_of(beyond, "point") +
                     " beyond 1000 m of the camera (check depth_scale and fx, fy)");
  }
  const std::size_t valid = cloud.count_valid();
  if (valid < std::max<std::size_t>(min_valid, 1)) {
    throw InputError(shown(path) + " has only " + count_of(valid, "pixel") +
                     " with depth (at least " +
                     std::to_string(std::max<std::size_t>(min_valid, 1)) + " needed)");
  }
}

}  // namespace

Cloud read_depth_png(const std::string& path, const std::string& content,
                     const std::string& intrinsics_path, std::size_t min_valid) {
  // The header and the intrinsics are checked before the pixels are decoded.
  const auto [width, height] = depth_png_size(content, path);
  const std::string found = find_depth_intrinsics(path, intrinsics_path);
  if (found.empty()) {
    const std::string sidecar = std::filesystem::path(path).stem().string() + ".json";
    throw InputError(shown(path) +
                     ": a depth PNG needs its intrinsics: give --intrinsics FILE, or put " +
                     shown(sidecar, 200) + " or intrinsics.json beside it");
  }
  const DepthIntrinsics k = parse_depth_intrinsics(read_all(found), found);
  const bool w_ok = k.width == 0 || k.width == width;
  const bool h_ok = k.height == 0 || k.height == height;
  if (!w_ok || !h_ok) {
    throw InputError(shown(path) + " is " + std::to_string(width) + "x" + std::to_string(height) +
                     " but its intrinsics " + shown(found) + " are for " + std::to_string(k.width) +
                     "x" + std::to_string(k.height));
  }
  Cloud cloud = depth_to_cloud(decode_depth_png(content, path), k);
  check_points(cloud, path, min_valid);
  return cloud;
}

}  // namespace groovetrace::io
