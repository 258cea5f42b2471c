// Helpers the PCD and PLY readers share (io/text.hpp).

#include "io/text.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <groovetrace/error.hpp>

namespace groovetrace::io {

void reject(std::string what) { throw Rejected{std::move(what)}; }

std::string rejected_message(const std::string& path, const Rejected& rejected) {
  // Messages that start with a verb read as a sentence about the file; others as a label.
  const std::string& what = rejected.what;
  const bool sentence = what.rfind("has ", 0) == 0 || what.rfind("cannot ", 0) == 0;
  return shown(path) + (sentence ? " " : ": ") + what;
}

std::string shown(std::string_view text, std::size_t max_len) {
  std::string out;
  for (char c : text.substr(0, max_len)) {
    out += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  if (text.size() > max_len) out += "...";
  return out;
}

std::string count_of(std::uint64_t n, const char* noun) {
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::string read_all(const std::string& path, bool allow_empty) {
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
  if (content.empty() && !allow_empty) throw InputError(shown(path) + " is empty");
  return content;
}

void require_shallow(const std::string& text, const std::string& path) {
  int depth = 0;
  bool quoted = false;
  for (std::size_t k = 0; k < text.size(); ++k) {
    const char c = text[k];
    if (quoted) {
      if (c == '\\') ++k;  // an escaped character, a quote among them
      quoted = c != '"';
    } else if (c == '"') {
      quoted = true;
    } else if (c == '[' || c == '{') {
      if (++depth > kMaxNesting) {
        throw InputError(shown(path) + " nests brackets deeper than " +
                         std::to_string(kMaxNesting) + " levels");
      }
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
}

std::string lower_extension(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  const std::size_t dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  std::string ext = path.substr(dot);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
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

std::string_view next_line(const std::string& content, std::size_t& pos) {
  std::size_t end = content.find('\n', pos);
  if (end == std::string::npos) end = content.size();
  const std::string_view line(content.data() + pos, end - pos);
  pos = std::min(end + 1, content.size());
  return line;
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

void require_fields(const std::vector<std::string>& names,
                    const std::vector<std::string>& required) {
  for (const std::string& want : required) {
    if (std::find(names.begin(), names.end(), want) != names.end()) continue;
    std::string list, wanted;
    for (const auto& n : names) list += (list.empty() ? "" : " ") + shown(n, 40);
    for (const auto& w : required) wanted += (wanted.empty() ? "" : "/") + shown(w, 40);
    reject("has no " + wanted + (required.size() == 1 ? " field" : " fields") +
           " (fields: " + (list.empty() ? std::string("none") : list) + ")");
  }
}

std::uint64_t checked_mul(std::uint64_t a, std::uint64_t b, const char* what) {
  if (a != 0 && b > kMaxDataBytes / a) reject(std::string(what) + " is too large");
  return a * b;
}

}  // namespace groovetrace::io
