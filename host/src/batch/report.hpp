#pragma once
// The night's summary from the scan directories: summary.csv, summary.json and index.html.

#include <string>
#include <vector>

#include "batch/row.hpp"

namespace groovetrace::batch {

/// Every scan.json under out_dir (OUTDIR/.partial aside), sorted by directory.
std::vector<ScanRow> collect_rows(const std::string& out_dir);

/// Wall time and scans run of the call that writes the report, for its frames per second
/// (a rebuilt report passes zeros and shows the scans' summed time instead).
struct RunStats {
  double seconds = 0;
  std::size_t scans_run = 0;
  int workers = 0;
};

/// Writes summary.csv, summary.json and index.html into out_dir, each atomically.
void write_report(const std::string& out_dir, const std::vector<ScanRow>& rows,
                  const RunStats& stats);

/// index.html's text: totals, the failures first with their messages, then every scan with its
/// picture and links to its files; relative links only, so it opens from the file system.
std::string index_html(const std::vector<ScanRow>& rows, const RunStats& stats,
                       const std::string& out_dir);

}  // namespace groovetrace::batch
