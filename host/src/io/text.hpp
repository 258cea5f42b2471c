#pragma once
// Helpers the PCD and PLY readers share: the whole file in memory, whitespace tokens, strict
// numbers, size limits, and the one-line reason a file was rejected.

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

namespace groovetrace::io {

// PCL keeps byte offsets in 32-bit integers; anything larger is not a depth frame anyway.
constexpr std::uint64_t kMaxDataBytes = std::numeric_limits<std::uint32_t>::max();

// The reason a file was rejected, without the path; the reader's entry point prefixes it
// (rejected_message) and throws InputError.
struct Rejected {
  std::string what;
};
[[noreturn]] void reject(std::string what);
// "PATH: malformed ..." or, for a reason that starts with a verb, "PATH has ...".
std::string rejected_message(const std::string& path, const Rejected& rejected);

// Paths and words from files go into one-line messages; a newline must not split them.
std::string shown(std::string_view text, std::size_t max_len = 4096);
// "1 value", "3 values": messages are read by people.
std::string count_of(std::uint64_t n, const char* noun);

// The file's bytes; InputError (one line, naming the path) if it is missing, not a regular
// file (a FIFO would hang the read, a directory read as nothing), unreadable, or empty unless
// `allow_empty`.
std::string read_all(const std::string& path, bool allow_empty = false);

// Throws InputError when `text` (a config or calibration file's, named `path`) nests its
// brackets or braces deeper than kMaxNesting: the YAML and JSON parsers recurse per level,
// and 100,000 nested '[' overflowed the stack (a segfault, nothing printed).
constexpr int kMaxNesting = 64;
void require_shallow(const std::string& text, const std::string& path);
// ".pcd" for "dir/Scan.PCD"; "" when the file name has no extension.
std::string lower_extension(const std::string& path);

// Blank-, tab- or CR-separated words of one line.
std::vector<std::string_view> split_ws(std::string_view line);
// The line that starts at `pos` (without its "\n"); moves `pos` past it.
std::string_view next_line(const std::string& content, std::size_t& pos);
bool parse_u64(std::string_view s, std::uint64_t& value);
// Any decimal number PCL may write, nan and inf included; locale-independent.
bool parse_number(std::string_view s, double& value);
// Rejects a file that lacks one of the `required` fields, listing the fields it has.
void require_fields(const std::vector<std::string>& names,
                    const std::vector<std::string>& required);
// a * b, rejected as "WHAT is too large" beyond kMaxDataBytes.
std::uint64_t checked_mul(std::uint64_t a, std::uint64_t b, const char* what);

}  // namespace groovetrace::io
