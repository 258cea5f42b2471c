#pragma once
// One scan's line in the night's summary, kept as scan.json in its directory so that any later
// call can rebuild the summary from the directories alone.

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace groovetrace::batch {

/// What happened to one scan. `status` is one of ok, no_groove, invalid_input, error, crashed,
/// timeout.
struct ScanRow {
  std::string scan;  ///< the input file
  std::string dir;   ///< its directory, relative to OUTDIR
  std::string status;
  int exit_code = 0;    ///< the exit code `run` gives for this outcome (crashed: -signal)
  std::string message;  ///< the one-line error, or the first warning, "" when none
  std::size_t points = 0, valid_points = 0, groove_points = 0;
  int seams = 0;              ///< accepted seams (robust) or kept parts (paper)
  int exported = 0;           ///< trajectories written
  std::size_t waypoints = 0;  ///< of the best trajectory
  double length_m = 0;        ///< of the best trajectory (m)
  std::vector<std::pair<std::string, double>> stages_ms;  ///< load, the method's stages, write
  double total_ms = 0;      ///< the scan's wall time in its worker (ms)
  std::string input_hash;   ///< FNV-1a 64 of the input file's bytes, hex
  std::string params_hash;  ///< FNV-1a 64 of the parameters as report.json lists them, hex
};

/// scan.json's text.
std::string row_json(const ScanRow& row);

/// Parses scan.json's text. Throws InputError naming `where` when it is not a row.
ScanRow row_from_json(const std::string& text, const std::string& where);

/// summary.csv's header line and one row's line (RFC 4180 quoting; stages as "name=ms;...").
std::string csv_header();
std::string csv_line(const ScanRow& row);

/// FNV-1a 64 of `size` bytes at `data`, continuing from `seed`.
std::uint64_t fnv1a64(const char* data, std::size_t size,
                      std::uint64_t seed = 14695981039346656037ull);

/// FNV-1a 64 of `bytes`.
inline std::uint64_t fnv1a64(const std::string& bytes) {
  return fnv1a64(bytes.data(), bytes.size());
}

/// 16 lower-case hex digits.
std::string hex64(std::uint64_t value);

/// fnv1a64 of a file's bytes as hex. Throws InputError when it cannot be read.
std::string file_hash(const std::string& path);

}  // namespace groovetrace::batch
