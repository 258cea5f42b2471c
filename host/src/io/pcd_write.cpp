// Writing binary PCDs by hand: the header is ours to the byte (field order, uint8 groove,
// exact VIEWPOINT), which pcl::PCDWriter would not give us without a matching point type.

#include <charconv>
#include <cmath>
#include <cstring>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <string>

// PCD binary data is the writer's memory layout, and every PCD reader in use assumes
// little-endian; a big-endian build would need byte swapping here.
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "pcd_write.cpp writes little-endian PCD data and needs a little-endian target"
#endif

namespace groovetrace {
namespace {

// Shortest text that reads back to the same float, and never a locale's decimal comma.
std::string float_text(float v) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

struct Layout {
  std::size_t width, height;
};

Layout layout_of(const Cloud& cloud) {
  const std::size_t n = cloud.size();
  if (cloud.y.size() != n || cloud.z.size() != n) {
    throw InternalError("cannot write a cloud whose x, y and z have different sizes");
  }
  if (!cloud.organized()) return {n, 1};  // width is ignored: 0 on a cloud built by resize()
  if (static_cast<std::size_t>(cloud.width) * cloud.height != n) {
    throw InternalError("cannot write an organized cloud of " + std::to_string(cloud.width) +
                        " x " + std::to_string(cloud.height) + " with " + std::to_string(n) +
                        " points");
  }
  return {cloud.width, cloud.height};
}

std::string header(const char* fields, const char* sizes, const char* types, const char* counts,
                   const Cloud& cloud) {
  const Layout layout = layout_of(cloud);
  if (!cloud.viewpoint.allFinite()) {
    throw InternalError("cannot write a cloud whose viewpoint is not finite");
  }
  std::string h = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  h += std::string("FIELDS ") + fields + "\nSIZE " + sizes + "\nTYPE " + types + "\nCOUNT " +
       counts + "\n";
  h += "WIDTH " + std::to_string(layout.width) + "\nHEIGHT " + std::to_string(layout.height) + "\n";
  h += "VIEWPOINT " + float_text(cloud.viewpoint.x()) + " " + float_text(cloud.viewpoint.y()) +
       " " + float_text(cloud.viewpoint.z()) + " 1 0 0 0\n";
  h += "POINTS " + std::to_string(cloud.size()) + "\nDATA binary\n";
  return h;
}

void check_size(std::size_t got, std::size_t n, const char* what) {
  if (got != n) {
    throw InternalError(std::string("cannot write ") + what + " for " + std::to_string(got) +
                        " points into a cloud of " + std::to_string(n));
  }
}

char* put(char* out, float v) {
  std::memcpy(out, &v, sizeof(v));
  return out + sizeof(v);
}

}  // namespace

std::string annotated_pcd_bytes(const Cloud& cloud, const Annotations& annotations) {
  std::string bytes = header("x y z normal_x normal_y normal_z descriptor groove",
                             "4 4 4 4 4 4 4 1", "F F F F F F F U", "1 1 1 1 1 1 1 1", cloud);
  const std::size_t n = cloud.size();
  const Normals* normals = annotations.normals;
  const std::vector<float>* descriptor = annotations.descriptor;
  const std::vector<std::uint8_t>* groove = annotations.groove;
  if (normals) {
    check_size(normals->x.size(), n, "normals");
    check_size(normals->y.size(), n, "normals");
    check_size(normals->z.size(), n, "normals");
  }
  if (descriptor) check_size(descriptor->size(), n, "descriptors");
  if (groove) check_size(groove->size(), n, "groove labels");

  constexpr std::size_t kPointBytes = 7 * sizeof(float) + 1;
  const std::size_t start = bytes.size();
  bytes.resize(start + n * kPointBytes);
  char* out = bytes.data() + start;
  for (std::size_t i = 0; i < n; ++i) {
    out = put(out, cloud.x[i]);
    out = put(out, cloud.y[i]);
    out = put(out, cloud.z[i]);
    out = put(out, normals ? normals->x[i] : NAN);
    out = put(out, normals ? normals->y[i] : NAN);
    out = put(out, normals ? normals->z[i] : NAN);
    out = put(out, descriptor ? (*descriptor)[i] : NAN);
    // The contract says 0/1; any other nonzero label still means groove.
    *out++ = static_cast<char>(groove && (*groove)[i] != 0 ? 1 : 0);
  }
  return bytes;
}

std::string pcd_bytes(const Cloud& cloud) {
  std::string bytes = header("x y z", "4 4 4", "F F F", "1 1 1", cloud);
  const std::size_t n = cloud.size();
  const std::size_t start = bytes.size();
  bytes.resize(start + n * 3 * sizeof(float));
  char* out = bytes.data() + start;
  for (std::size_t i = 0; i < n; ++i) {
    out = put(out, cloud.x[i]);
    out = put(out, cloud.y[i]);
    out = put(out, cloud.z[i]);
  }
  return bytes;
}

}  // namespace groovetrace
