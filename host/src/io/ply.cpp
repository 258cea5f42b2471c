// PLY files: the header's element counts checked against the file size, then PCL's decoder
// (io/decode.hpp says why).

#include <pcl/io/ply_io.h>

#include <string>
#include <string_view>

#include "io/decode.hpp"
#include "io/text.hpp"

namespace groovetrace::io {
namespace {

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

// PCL's PLY reader fills vertex colours by hand: a uchar red adds a 4-byte rgb field, blue
// writes it and moves on by 4 bytes, alpha amends it. Any other arrangement moves it past the
// point it fills (green and blue without red: an assertion in its reader, exit 134), so the
// vertex element's uchar colour properties, in order, must be one of these.
bool uchar_colour(std::string_view name) {
  for (const char* c :
       {"red", "green", "blue", "diffuse_red", "diffuse_green", "diffuse_blue", "alpha"}) {
    if (name == c) return true;
  }
  return false;
}

void check_colours(std::string colours) {
  // Properties after the colours do not matter; one between them does.
  while (colours.size() >= 2 && colours.compare(colours.size() - 2, 2, "| ") == 0) {
    colours.resize(colours.size() - 2);
  }
  for (const char* ok :
       {"", "red green blue ", "red green blue alpha ", "diffuse_red diffuse_green diffuse_blue ",
        "diffuse_red diffuse_green diffuse_blue alpha "}) {
    if (colours == ok) return;
  }
  reject("PLY vertex colours must be uchar red, green, blue (and alpha), one after another");
}

// The least number of data bytes the header's elements take, summed as the header is read,
// what PCL would build an organized grid from, and the vertex element's layout.
struct PlyBodySize {
  bool ascii = true;
  std::uint64_t min_body = 0, element_min = 0, element_count = 0;
  std::uint64_t file_size = 0, vertices = 0, cols = 0, rows = 0;
  bool has_cols = false, has_rows = false;
  bool in_vertex = false, seen_vertex = false;
  std::string colours;  // the vertex element's uchar colour properties, "|" for any other

  void close_element() {
    if (in_vertex) check_colours(colours);
    in_vertex = false;
    // An element with no properties takes no data bytes; its entries are still looped over
    // (2^64 - 1 of them kept PCL's reader busy for minutes).
    if (element_min == 0 && element_count > file_size) {
      reject("malformed PLY header: an element without properties declares " +
             std::to_string(element_count) + " entries, more than the file's " +
             std::to_string(file_size) + " bytes");
    }
    min_body += checked_mul(element_count, element_min, "an element count");
    if (min_body > kMaxDataBytes) reject("element counts are too large");
    element_min = element_count = 0;
  }
};

// PCL builds an organized cloud of obj_info's num_cols x num_rows points and fills it from
// the vertices: a grid that is not the vertices' own shape tripped an assertion in its
// reader (1 x 1 for 120 vertices: exit 134) or made a cloud of millions of empty points
// (2000 x 2000 from a 176-byte file).
void parse_obj_info(const std::vector<std::string_view>& tokens, int line_no, PlyBodySize& body) {
  if (tokens.size() < 2 || (tokens[1] != "num_cols" && tokens[1] != "num_rows")) return;
  const bool cols = tokens[1] == "num_cols";
  if (tokens.size() != 3 || !parse_u64(tokens[2], cols ? body.cols : body.rows)) {
    reject("malformed PLY header: line " + std::to_string(line_no) + " is a bad obj_info line");
  }
  (cols ? body.has_cols : body.has_rows) = true;
}

// range_grid elements, whose vertex indices PCL writes through unchecked (an index of -1
// crashed it), are not read.
void check_element(std::string_view name, PlyBodySize& body) {
  if (name == "range_grid") {
    reject("PLY range_grid elements are not read (save organized scans as PCD)");
  }
  if (name != "vertex") return;
  // PCL starts the cloud again at each vertex element but keeps the first one's count: the
  // second one's vertices were written past the data.
  if (body.seen_vertex) reject("malformed PLY header: a second vertex element");
  body.seen_vertex = body.in_vertex = true;
  body.vertices = body.element_count;
}

// PCL sizes a vertex list property by the first vertex's list and writes the others' through
// it (a longer one later: an assertion), so vertices are read without lists.
void check_vertex_property(const std::vector<std::string_view>& tokens, bool list,
                           PlyBodySize& body) {
  if (list) reject("PLY vertex list properties are not read");
  const std::string_view name = tokens[2];
  if ((tokens[1] == "uchar" || tokens[1] == "uint8") && uchar_colour(name)) {
    body.colours += std::string(name) + " ";
  } else if (!body.colours.empty()) {
    body.colours += "| ";
  }
}

// One header line after the magic; returns true at end_header.
bool parse_ply_line(const std::vector<std::string_view>& tokens, int line_no, bool& seen_format,
                    PlyBodySize& body) {
  const std::string_view key = tokens[0];
  if (key == "comment") return false;
  if (key == "obj_info") {
    parse_obj_info(tokens, line_no, body);
    return false;
  }
  if (key == "format") {
    if (tokens.size() != 3 || (tokens[1] != "ascii" && tokens[1] != "binary_little_endian" &&
                               tokens[1] != "binary_big_endian")) {
      reject("malformed PLY header: unknown format line");
    }
    seen_format = true;
    body.ascii = tokens[1] == "ascii";
  } else if (key == "element") {
    body.close_element();
    if (tokens.size() != 3 || !parse_u64(tokens[2], body.element_count)) {
      reject("malformed PLY header: line " + std::to_string(line_no) + " is a bad element line");
    }
    check_element(tokens[1], body);
  } else if (key == "property") {
    const bool list = tokens.size() == 5 && tokens[1] == "list";
    const std::uint64_t size =
        list ? ply_type_size(tokens[2]) : (tokens.size() == 3 ? ply_type_size(tokens[1]) : 0);
    if (size == 0 || (list && ply_type_size(tokens[3]) == 0)) {
      reject("malformed PLY header: line " + std::to_string(line_no) + " is a bad property line");
    }
    if (body.in_vertex) check_vertex_property(tokens, list, body);
    body.element_min += body.ascii ? 2 : size;
  } else if (key == "end_header") {
    body.close_element();
    return true;
  } else {
    reject("malformed PLY header: line " + std::to_string(line_no) + " ('" + shown(key, 20) +
           "') is not a PLY header line");
  }
  return false;
}

// PCL finds a header line's keyword past any white space, but hands an obj_info line to its
// callback as written, which splits it at blanks and tabs only and asserts that the first word
// is "obj_info": a leading blank made that word empty, and a leading carriage return (which
// split_ws skips) made it "\robj_info", both an assertion in its reader (exit 134); a vertical
// tab or form feed would too. A carriage return between words joined them for PCL alone:
// "obj_info\rx num_cols 1" set a grid that parse_obj_info never saw (1 x 1 for 120 vertices,
// the same assertion). A CRLF line end splits alike for both and is kept.
void check_pcl_split(std::string_view line, const std::vector<std::string_view>& tokens,
                     int line_no) {
  const char first = line.front();
  if (first == ' ' || first == '\t' || first == '\r' || first == '\v' || first == '\f') {
    reject("malformed PLY header: line " + std::to_string(line_no) + " starts with white space");
  }
  if (tokens[0] == "obj_info" && line.find('\r') < line.find_last_not_of('\r')) {
    reject("malformed PLY header: line " + std::to_string(line_no) +
           " has a carriage return between its words");
  }
}

// PCL's PLY reader sizes its buffers from the element counts before reading any data, so
// the counts are checked against the file size first: each value takes at least its size
// in binary, and at least a digit and a separator in ASCII (list properties at least their
// length prefix).
void check_ply_structure(const std::string& content) {
  std::size_t pos = 0;
  int line_no = 0;
  bool seen_format = false, seen_end = false;
  PlyBodySize body;
  body.file_size = content.size();
  while (!seen_end && pos < content.size()) {
    const std::string_view line = next_line(content, pos);
    const auto tokens = split_ws(line);
    ++line_no;
    if (line_no == 1) {
      if (tokens.size() != 1 || tokens[0] != "ply") reject("malformed PLY header: no 'ply' magic");
      continue;
    }
    if (tokens.empty()) continue;
    check_pcl_split(line, tokens, line_no);
    seen_end = parse_ply_line(tokens, line_no, seen_format, body);
  }
  if (!seen_end) reject("malformed PLY header: no end_header line");
  if (!seen_format) reject("malformed PLY header: no format line");
  if (body.has_cols != body.has_rows) reject("malformed PLY header: num_cols without num_rows");
  if (body.has_cols && checked_mul(body.cols, body.rows, "a grid size") != body.vertices) {
    reject("PLY obj_info grid " + std::to_string(body.cols) + " x " + std::to_string(body.rows) +
           " does not hold its " + std::to_string(body.vertices) + " vertices");
  }
  const std::uint64_t have = content.size() - pos;
  // The last ASCII value may end the file without a separator.
  const std::uint64_t need = body.ascii && body.min_body > 0 ? body.min_body - 1 : body.min_body;
  if (have < need) {
    reject("truncated PLY data: the header declares at least " + std::to_string(need) +
           " bytes of data, the file has " + std::to_string(have));
  }
}

}  // namespace

Decoded decode_ply(const std::string& path, const std::string& content) {
  Decoded out;
  quietly([&] {
    check_ply_structure(content);
    pcl::PLYReader reader;
    Eigen::Quaternionf orientation;
    int version = 0;
    // PLYReader takes only a path, so it reads the file again (from the page cache).
    if (reader.read(path, out.blob, out.origin, orientation, version) < 0) {
      reject("malformed or truncated PLY data (PCL cannot parse it)");
    }
    const pcl::PCLPointCloud2& blob = out.blob;
    if (blob.data.size() != static_cast<std::size_t>(blob.width) * blob.height * blob.point_step) {
      reject("malformed PLY data (PCL cannot decode it)");
    }
    // PCL 1.13 returns a zero origin even when the file has a camera element, but a later
    // version may not; an unusable one is ignored rather than trusted.
    if (!out.origin.head<3>().allFinite()) out.origin.setZero();
  });
  return out;
}

}  // namespace groovetrace::io
