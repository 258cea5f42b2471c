// Reading scans: PCD and PLY through PCL, behind our own checks of the file's structure.
//
// PCL 1.13 trusts the header it parses: an empty or header-only PCD crashes PCDReader::read,
// a huge POINTS or vertex count is allocated before any data is read (a 100-byte file can ask
// for 24 GB), a short or non-numeric ASCII line silently becomes a (0,0,0) point, and an
// unknown DATA type is read as ASCII. So every file is first checked here against its own
// header and size, and PCL only decodes what passed; its console output is silenced so the
// one-line InputError is the only thing a user sees.

#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace groovetrace {
namespace {

// PCL keeps byte offsets in 32-bit integers; anything larger is not a depth frame anyway.
constexpr std::uint64_t kMaxDataBytes = std::numeric_limits<std::uint32_t>::max();
// LZF's longest back-reference is 3 bytes for 264 output bytes, so no valid block expands
// more than 88 times; a larger claim is a corrupt header we must not allocate for.
constexpr std::uint64_t kMaxLzfRatio = 96;

// Paths go into one-line messages; a newline in a file name must not split them.
std::string shown(std::string_view text, std::size_t max_len = 4096) {
  std::string out;
  for (char c : text.substr(0, max_len)) {
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  if (text.size() > max_len) out += "...";
  return out;
}

// The reason a file was rejected, without the path; read_cloud prefixes it.
struct Rejected {
  std::string what;
};

[[noreturn]] void reject(std::string what) { throw Rejected{std::move(what)}; }

// "1 value", "3 values": messages are read by people.
std::string count_of(std::uint64_t n, const char* noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::vector<std::string_view> split_ws(std::string_view line) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    std::size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) tokens.push_back(line.substr(i, j - i));
    i = j;
  }
  return tokens;
}

bool parse_u64(std::string_view s, std::uint64_t& value) {
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  return ec == std::errc() && end == s.data() + s.size();
}

// from_chars is locale-independent (unlike strtod) and accepts nan/inf, as PCL writes them.
bool parse_number(std::string_view s, double& value) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  // Out-of-range values are still numbers (they become +-inf or 0 when decoded).
  return (ec == std::errc() || ec == std::errc::result_out_of_range) && end == s.data() + s.size();
}

std::uint64_t checked_mul(std::uint64_t a, std::uint64_t b, const char* what) {
  if (a != 0 && b > kMaxDataBytes / a) reject(std::string(what) + " is too large");
  return a * b;
}

// PCL prints its own errors (with "\n" and internal function names) to stderr. Silence it
// for the duration of a read; the counter keeps concurrent reads from restoring the level
// while another one is still running.
class PclQuiet {
 public:
  PclQuiet() {
    std::lock_guard<std::mutex> lock(mutex());
    if (users()++ == 0) {
      saved() = pcl::console::getVerbosityLevel();
      pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    }
  }
  ~PclQuiet() {
    std::lock_guard<std::mutex> lock(mutex());
    if (--users() == 0) pcl::console::setVerbosityLevel(saved());
  }
  PclQuiet(const PclQuiet&) = delete;
  PclQuiet& operator=(const PclQuiet&) = delete;

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  static int& users() {
    static int n = 0;
    return n;
  }
  static pcl::console::VERBOSITY_LEVEL& saved() {
    static pcl::console::VERBOSITY_LEVEL level = pcl::console::L_INFO;
    return level;
  }
};

std::string lower_extension(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string read_all(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    throw InputError("cannot read " + shown(path) + ": " + std::strerror(errno));
  }
  if (S_ISDIR(st.st_mode)) {
    throw InputError("cannot read " + shown(path) + ": it is a directory, not a file");
  }
  if (!S_ISREG(st.st_mode)) {
    throw InputError("cannot read " + shown(path) + ": not a regular file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot read " + shown(path) + ": " + std::strerror(errno));
  std::string content(static_cast<std::size_t>(st.st_size), '\0');
  in.read(content.data(), static_cast<std::streamsize>(content.size()));
  if (in.gcount() != static_cast<std::streamsize>(content.size())) {
    // The file shrank under us or the device failed; either way the data is not all there.
    throw InputError("cannot read " + shown(path) + ": read error");
  }
  if (content.empty()) throw InputError(shown(path) + " is empty");
  return content;
}

// ---- PCD --------------------------------------------------------------------------------

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

std::uint64_t header_u64(const std::vector<std::string_view>& tokens) {
  std::uint64_t v = 0;
  if (tokens.size() != 2 || !parse_u64(tokens[1], v)) {
    reject(std::string(tokens[0]) + " must be one non-negative integer");
  }
  return v;
}

// Strict parse of the header: a file PCL would misread must be rejected here, because
// PCL's own reader does not reject it (see the top of this file).
PcdHeader parse_pcd_header(const std::string& content) {
  PcdHeader h;
  bool seen_fields = false, seen_size = false, seen_type = false, seen_count = false;
  bool seen_width = false, seen_height = false, seen_points = false, seen_viewpoint = false;
  bool seen_data = false;
  std::size_t pos = 0;
  int line_no = 0;
  while (!seen_data && pos < content.size()) {
    std::size_t end = content.find('\n', pos);
    if (end == std::string::npos) end = content.size();
    const std::string_view line(content.data() + pos, end - pos);
    pos = std::min(end + 1, content.size());
    ++line_no;
    const auto tokens = split_ws(line);
    if (tokens.empty() || tokens[0].front() == '#') continue;
    const std::string_view key = tokens[0];
    const std::size_t n_args = tokens.size() - 1;
    auto once = [&](bool& seen) {
      if (seen) reject(std::string(key) + " appears twice");
      seen = true;
    };
    if (key == "VERSION") {
      continue;
    } else if (key == "FIELDS" || key == "COLUMNS") {
      once(seen_fields);
      if (n_args == 0) reject("FIELDS lists no fields");
      for (std::size_t i = 1; i < tokens.size(); ++i) {
        h.fields.push_back(PcdField{std::string(tokens[i])});
      }
    } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
      if (!seen_fields) reject(std::string(key) + " comes before FIELDS");
      if (key == "TYPE" && !seen_size) reject("TYPE comes before SIZE");
      if (key == "COUNT" && (!seen_size || !seen_type)) reject("COUNT comes before SIZE/TYPE");
      once(key == "SIZE" ? seen_size : key == "TYPE" ? seen_type : seen_count);
      if (n_args != h.fields.size()) {
        reject(std::string(key) + " has " + count_of(n_args, "value") + " but FIELDS has " +
               std::to_string(h.fields.size()));
      }
      for (std::size_t i = 0; i < n_args; ++i) {
        PcdField& f = h.fields[i];
        const std::string_view v = tokens[i + 1];
        std::uint64_t u = 0;
        if (key == "TYPE") {
          if (v != "F" && v != "I" && v != "U") {
            reject("TYPE of field " + shown(f.name, 40) + " is '" + shown(v, 20) +
                   "' (expected F, I or U)");
          }
          f.type = v.front();
        } else if (!parse_u64(v, u)) {
          reject(std::string(key) + " of field " + shown(f.name, 40) + " is not an integer");
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
    } else if (key == "WIDTH") {
      once(seen_width);
      h.width = header_u64(tokens);
    } else if (key == "HEIGHT") {
      once(seen_height);
      h.height = header_u64(tokens);
    } else if (key == "POINTS") {
      once(seen_points);
      h.points = header_u64(tokens);
    } else if (key == "VIEWPOINT") {
      once(seen_viewpoint);
      bool ok = n_args == 7;
      for (std::size_t i = 0; ok && i < 7; ++i) {
        ok = parse_number(tokens[i + 1], h.viewpoint[i]) && std::isfinite(h.viewpoint[i]);
      }
      if (!ok) reject("VIEWPOINT must be 7 finite numbers (tx ty tz qw qx qy qz)");
    } else if (key == "DATA") {
      once(seen_data);
      const std::string_view kind = n_args == 1 ? tokens[1] : std::string_view();
      if (kind == "ascii") {
        h.data = PcdData::kAscii;
      } else if (kind == "binary") {
        h.data = PcdData::kBinary;
      } else if (kind == "binary_compressed") {
        h.data = PcdData::kCompressed;
      } else {
        reject("unknown DATA type '" + shown(kind, 20) +
               "' (expected ascii, binary or binary_compressed)");
      }
      h.data_offset = pos;
    } else {
      reject("line " + std::to_string(line_no) + " ('" + shown(key, 20) +
             "') is not a PCD header line");
    }
  }
  if (!seen_data) reject("no DATA line");
  if (!seen_fields) reject("no FIELDS line");
  if (!seen_size) reject("no SIZE line");
  if (!seen_type) reject("no TYPE line");
  if (!seen_width) reject("no WIDTH line");
  if (!seen_points) reject("no POINTS line");
  for (const PcdField& f : h.fields) {
    if (f.type == 'F' && f.size != 4 && f.size != 8) {
      reject("field " + shown(f.name, 40) + " is a float of size " + std::to_string(f.size));
    }
    h.point_step += checked_mul(f.size, f.count, "a field");
    h.values += f.count;
  }
  // Division, not multiplication: the product of two 64-bit header values can wrap.
  const bool shape_ok =
      h.height == 0 ? h.points == 0 : h.points % h.height == 0 && h.points / h.height == h.width;
  if (!shape_ok) {
    reject("WIDTH x HEIGHT (" + std::to_string(h.width) + " x " + std::to_string(h.height) +
           ") is not POINTS (" + std::to_string(h.points) + ")");
  }
  checked_mul(h.points, h.point_step, "POINTS");
  return h;
}

std::uint32_t le_u32(const std::string& content, std::size_t at) {
  unsigned char b[4];
  std::memcpy(b, content.data() + at, 4);
  return static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
         static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
}

// Checks the data against the header. For ASCII, returns the data lines PCL is to decode:
// PCL counts a line holding only "\r" or blanks as a point, so those are dropped here and
// the rest passed on with "\n" endings.
std::string check_pcd_body(const std::string& content, const PcdHeader& h) {
  const std::uint64_t have = content.size() - h.data_offset;
  const std::uint64_t need = h.points * h.point_step;
  if (h.data == PcdData::kBinary) {
    if (have < need) {
      reject("truncated PCD data: " + count_of(h.points, "point") + " need " +
             std::to_string(need) + " bytes, the file has " + std::to_string(have));
    }
  } else if (h.data == PcdData::kCompressed) {
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
  } else {
    // PCL skips a line with the wrong number of values (leaving a zero point) and reads
    // words as 0, so every line is checked here.
    std::string lines;
    lines.reserve(content.size() - h.data_offset);
    std::uint64_t found = 0;
    std::size_t pos = h.data_offset;
    std::size_t line_no = static_cast<std::size_t>(
        std::count(content.begin(), content.begin() + static_cast<long>(pos), '\n'));
    while (found < h.points && pos < content.size()) {
      std::size_t end = content.find('\n', pos);
      if (end == std::string::npos) end = content.size();
      const std::string_view line(content.data() + pos, end - pos);
      pos = end + 1;
      ++line_no;
      const auto tokens = split_ws(line);
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
  return {};
}

void check_has_xyz(const std::vector<std::string>& names) {
  for (const char* want : {"x", "y", "z"}) {
    if (std::find(names.begin(), names.end(), want) == names.end()) {
      std::string list;
      for (const auto& n : names) list += (list.empty() ? "" : " ") + shown(n, 40);
      reject("has no x/y/z fields (fields: " + (list.empty() ? std::string("none") : list) + ")");
    }
  }
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

void decode_pcd(const std::string& content, pcl::PCLPointCloud2& blob, Eigen::Vector4f& origin) {
  PcdHeader h;
  try {
    h = parse_pcd_header(content);
  } catch (const Rejected& r) {
    reject("malformed PCD header: " + r.what);
  }
  const std::string ascii_lines = check_pcd_body(content, h);
  std::vector<std::string> names;
  for (const auto& f : h.fields) names.push_back(f.name);
  check_has_xyz(names);
  if (h.points == 0) reject("has no points");

  // The file is already in memory and checked; PCL decodes exactly these bytes.
  pcl::PCDReader reader;
  Eigen::Quaternionf orientation;
  int version = 0, data_type = 0;
  unsigned int data_idx = 0;
  const std::string clean = canonical_header(h);
  std::istringstream header(clean);
  if (reader.readHeader(header, blob, origin, orientation, version, data_type, data_idx) < 0 ||
      data_idx != clean.size() || blob.point_step != h.point_step) {
    reject("malformed PCD header (PCL cannot parse it)");
  }
  int result = 0;
  if (h.data == PcdData::kAscii) {
    std::istringstream body(ascii_lines);
    result = reader.readBodyASCII(body, blob, version);
  } else {
    const auto* data = reinterpret_cast<const unsigned char*>(content.data() + h.data_offset);
    result = reader.readBodyBinary(data, blob, version, h.data == PcdData::kCompressed, 0);
  }
  if (result < 0 || blob.data.size() != h.points * h.point_step ||
      static_cast<std::uint64_t>(blob.width) * blob.height != h.points) {
    reject("malformed PCD data (PCL cannot decode it)");
  }
}

// ---- PLY --------------------------------------------------------------------------------

std::uint64_t ply_type_size(std::string_view t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" ||
      t == "float32") {
    return 4;
  }
  if (t == "double" || t == "float64") return 8;
  return 0;
}

// PCL's PLY reader sizes its buffers from the element counts before reading any data, so
// the counts are checked against the file size first: each value takes at least its size
// in binary, and at least a digit and a separator in ASCII (list properties at least their
// length prefix).
void check_ply_structure(const std::string& content) {
  std::size_t pos = 0;
  int line_no = 0;
  bool ascii = true, seen_format = false, seen_end = false;
  std::uint64_t min_body = 0, element_min = 0, element_count = 0;
  auto close_element = [&]() {
    min_body += checked_mul(element_count, element_min, "an element count");
    if (min_body > kMaxDataBytes) reject("element counts are too large");
    element_min = element_count = 0;
  };
  while (!seen_end && pos < content.size()) {
    std::size_t end = content.find('\n', pos);
    if (end == std::string::npos) end = content.size();
    const std::string_view line(content.data() + pos, end - pos);
    pos = std::min(end + 1, content.size());
    ++line_no;
    const auto tokens = split_ws(line);
    if (line_no == 1) {
      if (tokens.size() != 1 || tokens[0] != "ply") reject("malformed PLY header: no 'ply' magic");
      continue;
    }
    if (tokens.empty()) continue;
    const std::string_view key = tokens[0];
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (tokens.size() != 3 || (tokens[1] != "ascii" && tokens[1] != "binary_little_endian" &&
                                 tokens[1] != "binary_big_endian")) {
        reject("malformed PLY header: unknown format line");
      }
      seen_format = true;
      ascii = tokens[1] == "ascii";
    } else if (key == "element") {
      close_element();
      if (tokens.size() != 3 || !parse_u64(tokens[2], element_count)) {
        reject("malformed PLY header: line " + std::to_string(line_no) + " is a bad element line");
      }
    } else if (key == "property") {
      const bool list = tokens.size() == 5 && tokens[1] == "list";
      const std::uint64_t size =
          list ? ply_type_size(tokens[2]) : (tokens.size() == 3 ? ply_type_size(tokens[1]) : 0);
      if (size == 0 || (list && ply_type_size(tokens[3]) == 0)) {
        reject("malformed PLY header: line " + std::to_string(line_no) + " is a bad property line");
      }
      element_min += ascii ? 2 : size;
    } else if (key == "end_header") {
      close_element();
      seen_end = true;
    } else {
      reject("malformed PLY header: line " + std::to_string(line_no) + " ('" + shown(key, 20) +
             "') is not a PLY header line");
    }
  }
  if (!seen_end) reject("malformed PLY header: no end_header line");
  if (!seen_format) reject("malformed PLY header: no format line");
  const std::uint64_t have = content.size() - pos;
  // The last ASCII value may end the file without a separator.
  if (ascii && min_body > 0) --min_body;
  if (have < min_body) {
    reject("truncated PLY data: the header declares at least " + std::to_string(min_body) +
           " bytes of data, the file has " + std::to_string(have));
  }
}

void decode_ply(const std::string& path, const std::string& content, pcl::PCLPointCloud2& blob,
                Eigen::Vector4f& origin) {
  check_ply_structure(content);
  pcl::PLYReader reader;
  Eigen::Quaternionf orientation;
  int version = 0;
  // PLYReader takes only a path, so it reads the file again (from the page cache).
  if (reader.read(path, blob, origin, orientation, version) < 0) {
    reject("malformed or truncated PLY data (PCL cannot parse it)");
  }
  if (blob.data.size() != static_cast<std::size_t>(blob.width) * blob.height * blob.point_step) {
    reject("malformed PLY data (PCL cannot decode it)");
  }
  // PCL 1.13 returns a zero origin even when the file has a camera element, but a later
  // version may not; an unusable one is ignored rather than trusted.
  if (!origin.head<3>().allFinite()) origin.setZero();
}

// ---- PCLPointCloud2 -> Cloud --------------------------------------------------------------

double field_value(const std::uint8_t* p, std::uint8_t datatype) {
  auto get = [p](auto v) {
    std::memcpy(&v, p, sizeof(v));
    return static_cast<double>(v);
  };
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return get(std::int8_t{});
    case pcl::PCLPointField::UINT8:
      return get(std::uint8_t{});
    case pcl::PCLPointField::INT16:
      return get(std::int16_t{});
    case pcl::PCLPointField::UINT16:
      return get(std::uint16_t{});
    case pcl::PCLPointField::INT32:
      return get(std::int32_t{});
    case pcl::PCLPointField::UINT32:
      return get(std::uint32_t{});
    case pcl::PCLPointField::INT64:
      return get(std::int64_t{});
    case pcl::PCLPointField::UINT64:
      return get(std::uint64_t{});
    case pcl::PCLPointField::FLOAT32:
      return get(float{});
    default:
      return get(double{});
  }
}

const pcl::PCLPointField& coordinate_field(const pcl::PCLPointCloud2& blob, const char* name) {
  for (const auto& f : blob.fields) {
    if (f.name != name) continue;
    const int size = pcl::getFieldSize(f.datatype);
    if (size == 0 || f.count == 0 ||
        f.offset + static_cast<std::uint64_t>(size) > blob.point_step) {
      reject(std::string("field ") + name + " has an unsupported type or layout");
    }
    return f;
  }
  reject("has no x/y/z fields");  // checked before; kept so every path returns or throws
}

Cloud to_cloud(const pcl::PCLPointCloud2& blob, const Eigen::Vector4f& origin, double scale,
               std::size_t min_valid) {
  std::vector<std::string> names;
  for (const auto& f : blob.fields) names.push_back(f.name);
  check_has_xyz(names);
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  if (n == 0) reject("has no points");

  const pcl::PCLPointField* fields[3] = {&coordinate_field(blob, "x"), &coordinate_field(blob, "y"),
                                         &coordinate_field(blob, "z")};
  Cloud cloud;
  cloud.resize(n);
  // A single column is a list of points, not an image one pixel wide.
  const bool organized = blob.height > 1 && blob.width > 1;
  cloud.width = organized ? blob.width : static_cast<std::uint32_t>(n);
  cloud.height = organized ? blob.height : 1;
  cloud.viewpoint = (origin.head<3>().cast<double>() * scale).cast<float>();

  std::vector<float>* out[3] = {&cloud.x, &cloud.y, &cloud.z};
  std::size_t infinite = 0;
  // Both readers return rows back to back (the data sizes were checked), so point i of the
  // file is at i * point_step whatever row_step says.
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = blob.data.data() + i * blob.point_step;
    float v[3];
    for (int k = 0; k < 3; ++k) {
      v[k] =
          static_cast<float>(field_value(point + fields[k]->offset, fields[k]->datatype) * scale);
    }
    // Coordinates beyond float range become inf here and are rejected with the infinities.
    if (std::isinf(v[0]) || std::isinf(v[1]) || std::isinf(v[2])) ++infinite;
    // A point missing any coordinate is no point at all; downstream tests x alone.
    if (std::isnan(v[0]) || std::isnan(v[1]) || std::isnan(v[2])) v[0] = v[1] = v[2] = NAN;
    for (int k = 0; k < 3; ++k) (*out[k])[i] = v[k];
  }
  if (infinite > 0) {
    reject("has " + count_of(infinite, "point") + " with infinite coordinates");
  }
  const std::size_t valid = cloud.count_valid();
  if (valid == 0) reject("has no valid points (all " + std::to_string(n) + " are NaN)");
  if (valid < min_valid) {
    reject("has only " + count_of(valid, "valid point") + " (at least " +
           std::to_string(min_valid) + " needed)");
  }
  return cloud;
}

}  // namespace

Cloud read_cloud(const std::string& path, const ReadOptions& options) {
  if (!(std::isfinite(options.units_scale) && options.units_scale > 0)) {
    throw UsageError("units scale must be a positive number, got " +
                     std::to_string(options.units_scale));
  }
  const std::string ext = lower_extension(path);
  if (ext != ".pcd" && ext != ".ply") {
    const std::string what = ext.empty() ? "no file extension" : "'" + shown(ext, 20) + "'";
    throw InputError("cannot read " + shown(path) + ": unsupported file type (" + what +
                     "; expected .pcd or .ply)");
  }
  const std::string content = read_all(path);
  try {
    PclQuiet quiet;
    pcl::PCLPointCloud2 blob;
    Eigen::Vector4f origin = Eigen::Vector4f::Zero();
    try {
      if (ext == ".pcd") {
        decode_pcd(content, blob, origin);
      } else {
        decode_ply(path, content, blob, origin);
      }
    } catch (const Rejected&) {
      throw;
    } catch (const std::exception& e) {
      reject(std::string("cannot be parsed (") + shown(e.what(), 200) + ")");
    } catch (...) {
      reject("cannot be parsed");
    }
    return to_cloud(blob, origin, options.units_scale, options.min_valid_points);
  } catch (const Rejected& r) {
    // Messages that start with a verb read as a sentence about the file; others as a label.
    const bool sentence = r.what.rfind("has ", 0) == 0 || r.what.rfind("cannot ", 0) == 0;
    throw InputError(shown(path) + (sentence ? " " : ": ") + r.what);
  }
}

}  // namespace groovetrace
