#include "batch/report.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/version.hpp>
#include <nlohmann/json.hpp>
#include <sstream>

#include "batch/scan_dir.hpp"

namespace groovetrace::batch {
namespace {

namespace fs = std::filesystem;

std::string html_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// A relative link to a file in the report's folder: each path segment percent-encoded.
std::string href(const std::string& rel) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : rel) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

std::string summary_json(const std::vector<ScanRow>& rows, const RunStats& stats) {
  nlohmann::json scans = nlohmann::json::array();
  for (const ScanRow& r : rows) scans.push_back(nlohmann::json::parse(row_json(r)));
  std::size_t ok = 0;
  for (const ScanRow& r : rows) ok += r.status == "ok" ? 1 : 0;
  const nlohmann::json j = {
      {"version", version()},
      {"scans", rows.size()},
      {"ok", ok},
      {"failed", rows.size() - ok},
      {"wall_s", stats.seconds},
      {"scans_run", stats.scans_run},
      {"frames_per_second", stats.seconds > 0 ? stats.scans_run / stats.seconds : 0.0},
      {"rows", scans}};
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

const char* kStyle =
    "body{font:14px sans-serif;margin:1.5em;color:#222}"
    "table{border-collapse:collapse}td,th{border-bottom:1px solid #ddd;padding:4px 8px;"
    "text-align:left;vertical-align:top}.ok{color:#176317}.bad{color:#a11;font-weight:bold}"
    "img{max-width:240px;border:1px solid #ccc}.totals span{margin-right:2em}";

std::string totals_html(const std::vector<ScanRow>& rows, const RunStats& stats) {
  std::size_t ok = 0;
  double summed_ms = 0;
  for (const ScanRow& r : rows) {
    ok += r.status == "ok" ? 1 : 0;
    summed_ms += r.total_ms;
  }
  std::string s = "<p class=\"totals\"><span>" + std::to_string(rows.size()) + " scans</span>" +
                  "<span class=\"ok\">" + std::to_string(ok) + " ok</span>" + "<span class=\"" +
                  (ok == rows.size() ? "ok" : "bad") + "\">" + std::to_string(rows.size() - ok) +
                  " failed</span>";
  if (stats.seconds > 0) {
    s += "<span>" + fmt("%.2f", stats.scans_run / stats.seconds) + " frames/s (" +
         std::to_string(stats.scans_run) + " scans in " + fmt("%.1f", stats.seconds) + " s, " +
         std::to_string(stats.workers) + " workers)</span>";
  }
  return s + "<span>" + fmt("%.0f", summed_ms / 1000) + " s of scan time</span></p>\n";
}

std::string failures_html(const std::vector<ScanRow>& rows) {
  std::string s;
  for (const ScanRow& r : rows) {
    if (r.status == "ok") continue;
    s += "<tr><td><a href=\"" + href(r.dir) + "/scan.json\">" + html_escape(r.dir) +
         "</a></td><td class=\"bad\">" + r.status + "</td><td>" + html_escape(r.message) +
         "</td></tr>\n";
  }
  if (s.empty()) return "<h2>Failures</h2><p>none</p>\n";
  return "<h2>Failures</h2><table><tr><th>scan</th><th>status</th><th>message</th></tr>\n" + s +
         "</table>\n";
}

// What a scan gave: its seams and best path, or why it gave nothing.
std::string result_cell(const ScanRow& r) {
  if (r.status != "ok") return "<small>" + html_escape(r.message) + "</small>";
  return std::to_string(r.seams) + (r.seams == 1 ? " seam" : " seams") + "<br>" +
         std::to_string(r.waypoints) + " waypoints<br>" + fmt("%.1f", r.length_m * 1000) + " mm";
}

std::string scan_row_html(const ScanRow& r, const std::string& out_dir) {
  const std::string d = href(r.dir);
  const bool has_picture = fs::exists(fs::path(out_dir) / r.dir / "thumbnail.png");
  std::string files;
  for (const char* f : {"report.json", "trajectory.csv", "program.script", "program.mod",
                        "program.src", "annotated.pcd"}) {
    if (fs::exists(fs::path(out_dir) / r.dir / f)) {
      files += "<a href=\"" + d + "/" + f + "\">" + f + "</a><br>";
    }
  }
  return "<tr class=\"scan\" data-dir=\"" + html_escape(r.dir) + "\"><td>" +
         (has_picture ? "<a href=\"" + d + "/overview.png\"><img src=\"" + d +
                            "/thumbnail.png\" alt=\"overview of " + html_escape(r.dir) + "\"></a>"
                      : std::string("")) +
         "</td><td>" + html_escape(r.dir) + "<br><small>" + html_escape(r.scan) +
         "</small></td><td class=\"" + (r.status == "ok" ? "ok" : "bad") + "\">" + r.status +
         "</td><td>" + result_cell(r) + "</td><td>" + fmt("%.0f", r.total_ms) + " ms</td><td>" +
         files + "<a href=\"" + d + "/scan.json\">scan.json</a></td></tr>\n";
}

}  // namespace

std::vector<ScanRow> collect_rows(const std::string& out_dir) {
  std::vector<ScanRow> rows;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(out_dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    if (it->path().filename() == ".partial") {
      it.disable_recursion_pending();
      continue;
    }
    if (it->path().filename() != "scan.json") continue;
    const std::string rel = fs::relative(it->path().parent_path(), out_dir).generic_string();
    ScanRow row;
    if (read_row(out_dir, rel, row)) rows.push_back(row);
  }
  if (ec) throw InputError("cannot list " + out_dir + ": " + ec.message());
  std::sort(rows.begin(), rows.end(),
            [](const ScanRow& a, const ScanRow& b) { return a.dir < b.dir; });
  return rows;
}

std::string index_html(const std::vector<ScanRow>& rows, const RunStats& stats,
                       const std::string& out_dir) {
  std::string s =
      "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
      "<title>groovetrace batch</title><style>" +
      std::string(kStyle) + "</style></head><body>\n<h1>groovetrace batch</h1>\n" +
      totals_html(rows, stats) +
      "<p><a href=\"summary.csv\">summary.csv</a> <a href=\"summary.json\">"
      "summary.json</a></p>\n" +
      failures_html(rows) +
      "<h2>Scans</h2><table id=\"scans\"><tr><th></th><th>scan</th><th>status</th>"
      "<th>result</th><th>time</th><th>files</th></tr>\n";
  for (const ScanRow& r : rows) s += scan_row_html(r, out_dir);
  return s + "</table>\n<p><small>groovetrace " + version() + "</small></p></body></html>\n";
}

void write_report(const std::string& out_dir, const std::vector<ScanRow>& rows,
                  const RunStats& stats) {
  std::string csv = csv_header();
  for (const ScanRow& r : rows) csv += csv_line(r);
  const fs::path dir(out_dir);
  write_file_atomic((dir / "summary.csv").string(), csv);
  write_file_atomic((dir / "summary.json").string(), summary_json(rows, stats));
  write_file_atomic((dir / "index.html").string(), index_html(rows, stats, out_dir));
}

}  // namespace groovetrace::batch
