// PCD files, the one place they are parsed and written: a strict header parse, the data
// checked against the header, PCL's decoder behind both (io/decode.hpp says why), the fields
// as named columns, and binary PCDs written by hand.

#include "io/pcd.hpp"

#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <set>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "io/decode.hpp"
#include "io/text.hpp"

// PCD binary data is the writer's memory layout, and every PCD reader in use assumes
// little-endian; a big-endian build would need byte swapping here.
#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "pcd.cpp writes little-endian PCD data and needs a little-endian target"
#endif

namespace groovetrace {
namespace io {
namespace {

// LZF's longest back-reference is 3 bytes for 264 output bytes, so no valid block expands
// more than 88 times; a larger claim is a corrupt header we must not allocate for.
constexpr std::uint64_t kMaxLzfRatio = 96;

// ---- reading: the header ----------------------------------------------------------------

struct PcdField {
  std::string name;
  std::uint64_t size = 4;
  char type = 'F';
  std::uint64_t count = 1;
};

enum class PcdData { kAscii, kBinary, kCompressed };

struct PcdHeader {
  std::vector<PcdField> fields;
  std::uint64_t width = 0, height = 1, points = 0;
  std::uint64_t point_step = 0;                 // bytes per point
  std::uint64_t values = 0;                     // numbers per point (ASCII tokens per line)
  double viewpoint[7] = {0, 0, 0, 1, 0, 0, 0};  // tx ty tz qw qx qy qz
  PcdData data = PcdData::kAscii;
  std::size_t data_offset = 0;  // first byte after the DATA line
};

using Tokens = std::vector<std::string_view>;

std::uint64_t header_u64(const Tokens& tokens) {
  std::uint64_t v = 0;
  if (tokens.size() != 2 || !parse_u64(tokens[1], v)) {
    reject(std::string(tokens[0]) + " must be one non-negative integer");
  }
  return v;
}

// Strict parse of the header: a file PCL would misread must be rejected here, because
// PCL's own reader does not reject it (io/decode.hpp).
class HeaderParser {
 public:
  explicit HeaderParser(const std::string& content) : content_(content) {}

  PcdHeader parse() {
    int line_no = 0;
    while (!seen("DATA") && pos_ < content_.size()) {
      const Tokens tokens = split_ws(next_line(content_, pos_));
      ++line_no;
      if (tokens.empty() || tokens[0].front() == '#') continue;
      parse_line(tokens, line_no);
    }
    finish();
    return h_;
  }

 private:
  bool seen(const char* key) const { return seen_.count(key) > 0; }
  // `key` as written; `canonical` is the key it stands for (COLUMNS is FIELDS).
  void once(std::string_view key, const char* canonical) {
    if (!seen_.insert(canonical).second) reject(std::string(key) + " appears twice");
  }

  void parse_line(const Tokens& tokens, int line_no) {
    const std::string_view key = tokens[0];
    if (key == "VERSION") return;
    if (key == "FIELDS" || key == "COLUMNS") return parse_fields(tokens);
    if (key == "SIZE" || key == "TYPE" || key == "COUNT") return parse_field_property(tokens);
    if (key == "VIEWPOINT") return parse_viewpoint(tokens);
    if (key == "DATA") return parse_data(tokens);
    std::uint64_t* target = key == "WIDTH"    ? &h_.width
                            : key == "HEIGHT" ? &h_.height
                            : key == "POINTS" ? &h_.points
                                              : nullptr;
    if (target == nullptr) {
      reject("line " + std::to_string(line_no) + " ('" + shown(key, 20) +
             "') is not a PCD header line");
    }
    once(key, key == "WIDTH" ? "WIDTH" : key == "HEIGHT" ? "HEIGHT" : "POINTS");
    *target = header_u64(tokens);
  }

  void parse_fields(const Tokens& tokens) {
    once(tokens[0], "FIELDS");
    if (tokens.size() == 1) reject("FIELDS lists no fields");
    for (std::size_t i = 1; i < tokens.size(); ++i) {
      h_.fields.push_back(PcdField{std::string(tokens[i])});
    }
  }

  // SIZE, TYPE and COUNT: one value per field, in this order.
  void parse_field_property(const Tokens& tokens) {
    const std::string key(tokens[0]);
    const std::size_t n_args = tokens.size() - 1;
    if (!seen("FIELDS")) reject(key + " comes before FIELDS");
    if (key == "TYPE" && !seen("SIZE")) reject("TYPE comes before SIZE");
    if (key == "COUNT" && (!seen("SIZE") || !seen("TYPE"))) {
      reject("COUNT comes before SIZE/TYPE");
    }
    once(key, key == "SIZE" ? "SIZE" : key == "TYPE" ? "TYPE" : "COUNT");
    if (n_args != h_.fields.size()) {
      reject(key + " has " + count_of(n_args, "value") + " but FIELDS has " +
             std::to_string(h_.fields.size()));
    }
    for (std::size_t i = 0; i < n_args; ++i) set_property(key, tokens[i + 1], h_.fields[i]);
  }

  static void set_property(const std::string& key, std::string_view v, PcdField& f) {
    std::uint64_t u = 0;
    if (key == "TYPE") {
      if (v != "F" && v != "I" && v != "U") {
        reject("TYPE of field " + shown(f.name, 40) + " is '" + shown(v, 20) +
               "' (expected F, I or U)");
      }
      f.type = v.front();
    } else if (!parse_u64(v, u)) {
      reject(key + " of field " + shown(f.name, 40) + " is not an integer");
    } else if (key == "SIZE") {
      if (u != 1 && u != 2 && u != 4 && u != 8) {
        reject("SIZE of field " + shown(f.name, 40) + " is " + std::to_string(u) +
               " (expected 1, 2, 4 or 8)");
      }
      f.size = u;
    } else {
      if (u == 0) reject("COUNT of field " + shown(f.name, 40) + " is 0");
      f.count = u;
    }
  }

  void parse_viewpoint(const Tokens& tokens) {
    once(tokens[0], "VIEWPOINT");
    bool ok = tokens.size() == 8;
    for (std::size_t i = 0; ok && i < 7; ++i) {
      ok = parse_number(tokens[i + 1], h_.viewpoint[i]) && std::isfinite(h_.viewpoint[i]);
    }
    if (!ok) reject("VIEWPOINT must be 7 finite numbers (tx ty tz qw qx qy qz)");
  }

  void parse_data(const Tokens& tokens) {
    once(tokens[0], "DATA");
    const std::string_view kind = tokens.size() == 2 ? tokens[1] : std::string_view();
    if (kind == "ascii") {
      h_.data = PcdData::kAscii;
    } else if (kind == "binary") {
      h_.data = PcdData::kBinary;
    } else if (kind == "binary_compressed") {
      h_.data = PcdData::kCompressed;
    } else {
      reject("unknown DATA type '" + shown(kind, 20) +
             "' (expected ascii, binary or binary_compressed)");
    }
    h_.data_offset = pos_;
  }

  // The lines every header needs, and the sizes they imply.
  void finish() {
    for (const char* key : {"DATA", "FIELDS", "SIZE", "TYPE", "WIDTH", "POINTS"}) {
      if (!seen(key)) reject(std::string("no ") + key + " line");
    }
    for (const PcdField& f : h_.fields) {
      if (f.type == 'F' && f.size != 4 && f.size != 8) {
        reject("field " + shown(f.name, 40) + " is a float of size " + std::to_string(f.size));
      }
      h_.point_step += checked_mul(f.size, f.count, "a field");
      h_.values += f.count;
    }
    // Division, not multiplication: the product of two 64-bit header values can wrap.
    const bool shape_ok = h_.height == 0
                              ? h_.points == 0
                              : h_.points % h_.height == 0 && h_.points / h_.height == h_.width;
    if (!shape_ok) {
      reject("WIDTH x HEIGHT (" + std::to_string(h_.width) + " x " + std::to_string(h_.height) +
             ") is not POINTS (" + std::to_string(h_.points) + ")");
    }
    checked_mul(h_.points, h_.point_step, "POINTS");
  }

  const std::string& content_;
  std::size_t pos_ = 0;
  PcdHeader h_;
  std::set<std::string, std::less<>> seen_;
};

PcdHeader parse_header(const std::string& content) {
  try {
    return HeaderParser(content).parse();
  } catch (const Rejected& r) {
    reject("malformed PCD header: " + r.what);
  }
}

// ---- reading: the data ------------------------------------------------------------------

std::uint32_t le_u32(const std::string& content, std::size_t at) {
  unsigned char b[4];
  std::memcpy(b, content.data() + at, 4);
  return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
         static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
}

void check_binary_data(const std::string& content, const PcdHeader& h) {
  const std::uint64_t have = content.size() - h.data_offset;
  const std::uint64_t need = h.points * h.point_step;
  if (have < need) {
    reject("truncated PCD data: " + count_of(h.points, "point") + " need " + std::to_string(need) +
           " bytes, the file has " + std::to_string(have));
  }
}

void check_compressed_data(const std::string& content, const PcdHeader& h) {
  const std::uint64_t have = content.size() - h.data_offset;
  const std::uint64_t need = h.points * h.point_step;
  if (have < 8) reject("truncated PCD data: the compressed block header is missing");
  const std::uint64_t packed = le_u32(content, h.data_offset);
  const std::uint64_t unpacked = le_u32(content, h.data_offset + 4);
  if (have - 8 < packed) {
    reject("truncated PCD data: the compressed block has " + std::to_string(have - 8) + " of " +
           std::to_string(packed) + " bytes");
  }
  if (unpacked != need || need > kMaxLzfRatio * packed + 64) {
    reject("malformed PCD data: the compressed block decodes to " + std::to_string(unpacked) +
           " bytes, " + count_of(h.points, "point") + " need " + std::to_string(need));
  }
}

// PCL skips a line with the wrong number of values (leaving a zero point) and reads words
// as 0, so every line is checked here. Returns the data lines PCL is to decode: PCL counts a
// line holding only "\r" or blanks as a point, so those are dropped and the rest passed on
// with "\n" endings.
std::string checked_ascii_lines(const std::string& content, const PcdHeader& h) {
  std::string lines;
  lines.reserve(content.size() - h.data_offset);
  std::uint64_t found = 0;
  std::size_t pos = h.data_offset;
  auto line_no = static_cast<std::size_t>(
      std::count(content.begin(), content.begin() + static_cast<long>(pos), '\n'));
  while (found < h.points && pos < content.size()) {
    const Tokens tokens = split_ws(next_line(content, pos));
    ++line_no;
    if (tokens.empty()) continue;
    ++found;
    if (tokens.size() != h.values) {
      const bool last = pos >= content.size();
      reject(std::string(last && tokens.size() < h.values ? "truncated" : "malformed") +
             " PCD data: line " + std::to_string(line_no) + " has " +
             count_of(tokens.size(), "value") + ", expected " + std::to_string(h.values));
    }
    double v = 0;
    for (std::string_view t : tokens) {
      if (!parse_number(t, v)) {
        reject("malformed PCD data: line " + std::to_string(line_no) + ": '" + shown(t, 20) +
               "' is not a number");
      }
      lines.append(t.data(), t.size()).push_back(' ');
    }
    lines.back() = '\n';
  }
  if (found < h.points) {
    reject("truncated PCD data: " + std::to_string(found) + " of " + std::to_string(h.points) +
           " points present");
  }
  return lines;
}

std::string number_text(double v) {
  char buf[32];
  return std::string(buf, std::to_chars(buf, buf + sizeof(buf), v).ptr);
}

// The header as PCL's parser expects it. PCL stops at lines it does not know (a lone "\r",
// a misspelt keyword it matches by prefix), so it is given this clean copy of what was
// parsed above rather than the file's own text; the two then cannot disagree.
std::string canonical_header(const PcdHeader& h) {
  std::string fields = "FIELDS", sizes = "SIZE", types = "TYPE", counts = "COUNT";
  for (const PcdField& f : h.fields) {
    fields += " " + f.name;
    sizes += " " + std::to_string(f.size);
    types += std::string(" ") + f.type;
    counts += " " + std::to_string(f.count);
  }
  std::string viewpoint = "VIEWPOINT";
  for (double v : h.viewpoint) viewpoint += " " + number_text(v);
  const char* kind = h.data == PcdData::kAscii    ? "ascii"
                     : h.data == PcdData::kBinary ? "binary"
                                                  : "binary_compressed";
  return "VERSION 0.7\n" + fields + "\n" + sizes + "\n" + types + "\n" + counts + "\nWIDTH " +
         std::to_string(h.width) + "\nHEIGHT " + std::to_string(h.height) + "\n" + viewpoint +
         "\nPOINTS " + std::to_string(h.points) + "\nDATA " + kind + "\n";
}

// PCL decodes exactly the checked bytes (the file is already in memory).
void decode_checked(const std::string& content, const PcdHeader& h, const std::string& ascii_lines,
                    Decoded& out) {
  pcl::PCDReader reader;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_idx = 0;
  const std::string clean = canonical_header(h);
  std::istringstream header(clean);
  const int parsed =
      reader.readHeader(header, out.blob, out.origin, orientation, version, data_type, data_idx);
  if (parsed < 0 || data_idx != clean.size() || out.blob.point_step != h.point_step) {
    reject("malformed PCD header (PCL cannot parse it)");
  }
  int result = 0;
  if (h.data == PcdData::kAscii) {
    std::istringstream body(ascii_lines);
    result = reader.readBodyASCII(body, out.blob, version);
  } else {
    const auto* data = reinterpret_cast<const unsigned char*>(content.data() + h.data_offset);
    result = reader.readBodyBinary(data, out.blob, version, h.data == PcdData::kCompressed, 0);
  }
  if (result < 0 || out.blob.data.size() != h.points * h.point_step ||
      static_cast<std::uint64_t>(out.blob.width) * out.blob.height != h.points) {
    reject("malformed PCD data (PCL cannot decode it)");
  }
}

PcdTable to_table(const Decoded& d) {
  const pcl::PCLPointCloud2& blob = d.blob;
  PcdTable table;
  table.width = blob.width;
  table.height = blob.height;
  table.viewpoint = d.origin.head<3>();
  const std::size_t n = table.size();
  for (const pcl::PCLPointField& listed : blob.fields) {
    if (listed.count != 1) continue;
    const pcl::PCLPointField& f = blob_field(blob, listed.name);
    std::vector<float> column(n);
    // PCL returns the points back to back (the data size was checked).
    for (std::size_t i = 0; i < n; ++i) {
      column[i] = static_cast<float>(
          field_value(blob.data.data() + i * blob.point_step + f.offset, f.datatype));
    }
    table.names.push_back(f.name);
    table.columns.push_back(std::move(column));
  }
  return table;
}

// ---- writing ----------------------------------------------------------------------------

// Shortest text that reads back to the same float, and never a locale's decimal comma.
std::string float_text(float v) {
  char buf[32];
  const auto result = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, result.ptr);
}

void write_column(const PcdColumn& c, std::size_t n, std::size_t point_bytes, char* out) {
  for (std::size_t i = 0; i < n; ++i, out += point_bytes) {
    if (c.is_flag) {
      *out = static_cast<char>(c.flags && (*c.flags)[i] != 0 ? 1 : 0);
    } else {
      const float v = c.floats ? (*c.floats)[i] : NAN;
      std::memcpy(out, &v, sizeof(v));
    }
  }
}

// A cloud's x y z, then `more`, in its shape; an unorganized cloud is a list of its points
// (its width is ignored: 0 on a cloud built by resize()). PCL's usual first line.
std::string cloud_pcd_bytes(const Cloud& cloud, const std::vector<PcdColumn>& more) {
  std::vector<PcdColumn> columns = {float_column("x", &cloud.x), float_column("y", &cloud.y),
                                    float_column("z", &cloud.z)};
  columns.insert(columns.end(), more.begin(), more.end());
  return binary_pcd_bytes("Point Cloud Data file format",
                          cloud.organized() ? cloud.width : cloud.size(),
                          cloud.organized() ? cloud.height : 1, cloud.viewpoint, columns);
}

}  // namespace

// ---- reading ----------------------------------------------------------------------------

Decoded decode_pcd(const std::string& content, const std::vector<std::string>& required) {
  Decoded out;
  quietly([&] {
    const PcdHeader h = parse_header(content);
    std::string ascii_lines;
    if (h.data == PcdData::kBinary) {
      check_binary_data(content, h);
    } else if (h.data == PcdData::kCompressed) {
      check_compressed_data(content, h);
    } else {
      ascii_lines = checked_ascii_lines(content, h);
    }
    std::vector<std::string> names;
    for (const PcdField& f : h.fields) names.push_back(f.name);
    require_fields(names, required);
    if (h.points == 0) reject("has no points");
    decode_checked(content, h, ascii_lines, out);
  });
  return out;
}

const std::vector<float>* PcdTable::column(const std::string& name) const {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? nullptr : &columns[static_cast<std::size_t>(it - names.begin())];
}

PcdTable read_pcd_fields(const std::string& path, const std::vector<std::string>& required) {
  const std::string content = read_all(path);
  try {
    PcdTable table = to_table(decode_pcd(content, required));
    for (const std::string& name : required) {
      if (!table.column(name)) reject("field " + shown(name, 40) + " has COUNT > 1");
    }
    return table;
  } catch (const Rejected& r) {
    throw InputError(rejected_message(path, r));
  }
}

// ---- writing ----------------------------------------------------------------------------

PcdColumn float_column(std::string name, const std::vector<float>* values) {
  return PcdColumn{std::move(name), values, nullptr, false};
}

PcdColumn flag_column(std::string name, const std::vector<std::uint8_t>* values) {
  return PcdColumn{std::move(name), nullptr, values, true};
}

std::string binary_pcd_bytes(const std::string& comment, std::size_t width, std::size_t height,
                             const Eigen::Vector3f& viewpoint,
                             const std::vector<PcdColumn>& columns) {
  if (!viewpoint.allFinite()) {
    throw InternalError("cannot write a cloud whose viewpoint is not finite");
  }
  const std::size_t n = width * height;
  std::string fields = "FIELDS", sizes = "SIZE", types = "TYPE", counts = "COUNT";
  std::size_t point_bytes = 0;
  for (const PcdColumn& c : columns) {
    const std::size_t got =
        c.is_flag ? (c.flags ? c.flags->size() : n) : (c.floats ? c.floats->size() : n);
    if (got != n) {
      throw InternalError("cannot write " + count_of(got, "value") + " of " + c.name +
                          " into a PCD of " + std::to_string(width) + " x " +
                          std::to_string(height) + " points");
    }
    fields += " " + c.name;
    sizes += c.is_flag ? " 1" : " 4";
    types += c.is_flag ? " U" : " F";
    counts += " 1";
    point_bytes += c.is_flag ? 1 : sizeof(float);
  }
  std::string bytes =
      "# .PCD v0.7 - " + comment + "\nVERSION 0.7\n" + fields + "\n" + sizes + "\n" + types + "\n" +
      counts + "\nWIDTH " + std::to_string(width) + "\nHEIGHT " + std::to_string(height) +
      "\nVIEWPOINT " + float_text(viewpoint.x()) + " " + float_text(viewpoint.y()) + " " +
      float_text(viewpoint.z()) + " 1 0 0 0\nPOINTS " + std::to_string(n) + "\nDATA binary\n";
  std::size_t offset = bytes.size();
  bytes.resize(offset + n * point_bytes);
  for (const PcdColumn& c : columns) {
    write_column(c, n, point_bytes, bytes.data() + offset);
    offset += c.is_flag ? 1 : sizeof(float);
  }
  return bytes;
}

}  // namespace io

std::string pcd_bytes(const Cloud& cloud) { return io::cloud_pcd_bytes(cloud, {}); }

std::string annotated_pcd_bytes(const Cloud& cloud, const Annotations& annotations) {
  const Normals* normals = annotations.normals;
  return io::cloud_pcd_bytes(cloud,
                             {io::float_column("normal_x", normals ? &normals->x : nullptr),
                              io::float_column("normal_y", normals ? &normals->y : nullptr),
                              io::float_column("normal_z", normals ? &normals->z : nullptr),
                              io::float_column("descriptor", annotations.descriptor),
                              // The contract says 0/1; any other nonzero label still means groove.
                              io::flag_column("groove", annotations.groove)});
}

}  // namespace groovetrace
