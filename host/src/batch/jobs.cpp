#include "batch/jobs.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <map>
#include <set>
#include <sstream>

#include "io/depth_png.hpp"
#include "io/text.hpp"

namespace groovetrace::batch {
namespace {

namespace fs = std::filesystem;

// The pictures `run` and `batch` write beside their report.json or scan.json.
bool is_run_picture(const fs::path& p) {
  const std::string name = p.filename().string();
  if (name != "overview.png" && name != "thumbnail.png") return false;
  std::error_code ec;
  return fs::exists(p.parent_path() / "report.json", ec) ||
         fs::exists(p.parent_path() / "scan.json", ec);
}

// A .png is a depth scan when its intrinsics are found (--intrinsics, STEM.json or
// intrinsics.json beside it); other PNGs (photos, a run's pictures) are no scans.
bool is_scan(const fs::path& p, const ListOptions& options) {
  const std::string ext = io::lower_extension(p.string());
  if (ext == ".png") {
    if (is_run_picture(p)) return false;
    return options.intrinsics_given || !io::find_depth_intrinsics(p.string(), "").empty();
  }
  return ext == ".pcd" || ext == ".ply";
}

// Whether `p` is the batch's own OUTDIR (when it lies inside an input folder).
bool is_out_dir(const fs::path& p, const ListOptions& options) {
  std::error_code ec;
  return !options.out_dir.empty() && fs::equivalent(p, options.out_dir, ec);
}

// `groovetrace synth` writes SCAN.pcd with its ground truth beside it: SCAN.truth.json and
// SCAN.labels.pcd. The labels are not a scan.
bool is_synth_labels(const fs::path& p) {
  const std::string name = p.filename().string();
  const std::string suffix = ".labels.pcd";
  if (name.size() <= suffix.size() ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0) {
    return false;
  }
  const std::string stem = name.substr(0, name.size() - suffix.size());
  std::error_code ec;
  return fs::exists(p.parent_path() / (stem + ".truth.json"), ec);
}

// A scan's directory: its path without the extension. The stem of "..pcd" is ".", which named
// OUTDIR itself; a file whose stem is "." or ".." keeps its extension.
std::string without_extension(const fs::path& rel) {
  const fs::path stem = rel.stem();
  const bool dots = stem.empty() || stem == "." || stem == "..";
  return (rel.parent_path() / (dots ? rel.filename() : stem)).generic_string();
}

std::vector<ScanJob> scans_in_directory(const fs::path& root, const ListOptions& options) {
  std::vector<ScanJob> jobs;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    if (it->is_directory(ec) && is_out_dir(it->path(), options)) {
      it.disable_recursion_pending();  // the batch's own outputs are no scans
      continue;
    }
    if (!it->is_regular_file(ec) || !is_scan(it->path(), options) || is_synth_labels(it->path())) {
      continue;
    }
    jobs.push_back({it->path().string(), without_extension(fs::relative(it->path(), root)), "", "",
                    std::nullopt});
  }
  if (ec) throw InputError("cannot list " + root.string() + ": " + ec.message());
  return jobs;
}

// A CSV line split at commas outside double quotes ("" inside quotes is a quote).
std::vector<std::string> csv_cells(const std::string& line) {
  std::vector<std::string> cells(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '"' && quoted && i + 1 < line.size() && line[i + 1] == '"') {
      cells.back() += '"';
      ++i;
    } else if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      cells.emplace_back();
    } else if (c != '\r') {
      cells.back() += c;
    }
  }
  return cells;
}

Eigen::Vector3f parse_viewpoint(const std::string& text, const std::string& where) {
  std::istringstream in(text);
  Eigen::Vector3f v;
  std::string rest;
  if (!(in >> v.x() >> v.y() >> v.z()) || (in >> rest) || !v.allFinite()) {
    throw InputError(where + ": viewpoint must be three numbers \"X Y Z\" (m), got '" + text + "'");
  }
  return v;
}

// A manifest row's directory under OUTDIR: its scan path without extension, without the parts
// that would leave OUTDIR. The batch replaces a scan's directory whole (and removes the old
// one): "../x.pcd" or "/data/x.pcd" named OUTDIR/../x or /data/x before.
std::string rel_inside(const std::string& scan) {
  fs::path rel;
  for (const fs::path& part : fs::path(scan).lexically_normal().relative_path()) {
    if (!part.empty() && part != "." && part != "..") rel /= part;
  }
  return rel.empty() ? std::string("scan") : without_extension(rel);
}

std::string extension_of(const ScanJob& job) {
  const std::string ext = io::lower_extension(job.path);
  return ext.empty() ? ext : ext.substr(1);
}

// What the batch itself keeps in OUTDIR (batch/report.cpp's summaries and page, pool.cpp's
// staging folder): a scan named summary.csv.pcd or .partial.pcd must not get one of these.
const char* const kBatchOwn[] = {"summary.csv", "summary.json", "index.html", ".partial"};

// Makes every job's directory unique: where scans of different types share one, each gets its
// extension (x.pcd, x.ply: x_pcd, x_ply); scans that still share one, or that share the
// batch's own names, are counted (s1, s1_2; summary.csv_2).
void make_unique(std::vector<ScanJob>& jobs) {
  std::map<std::string, std::set<std::string>> extensions;
  for (const ScanJob& j : jobs) extensions[j.rel].insert(extension_of(j));
  for (ScanJob& j : jobs) {
    if (extensions[j.rel].size() > 1) j.rel += "_" + extension_of(j);
  }
  // A counted name may be another scan's own (a, a and a_2): counting goes on past those.
  std::set<std::string> taken(std::begin(kBatchOwn), std::end(kBatchOwn));
  for (const ScanJob& j : jobs) taken.insert(j.rel);
  std::map<std::string, int> seen;
  for (const char* own : kBatchOwn) seen[own] = 1;
  for (ScanJob& j : jobs) {
    if (seen[j.rel]++ == 0) continue;
    int n = 2;
    while (!taken.insert(j.rel + "_" + std::to_string(n)).second) ++n;
    j.rel += "_" + std::to_string(n);
  }
}

}  // namespace

std::vector<ScanJob> read_manifest(const std::string& path) {
  std::istringstream in(io::read_all(path));  // a regular file: a FIFO would hang the batch
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = csv_cells(line);
  std::map<std::string, std::size_t> column;
  for (std::size_t c = 0; c < header.size(); ++c) column[header[c]] = c;
  if (!column.count("scan")) {
    // shown(): the line may end in the "\r" of a CRLF file, which would split the message.
    throw InputError("manifest " + path + ": the header must name a 'scan' column, got '" +
                     io::shown(line, 200) + "'");
  }
  const fs::path base = fs::path(path).parent_path();
  auto file = [&](const std::vector<std::string>& row, const char* name) -> std::string {
    if (!column.count(name) || row.size() <= column[name] || row[column[name]].empty()) return "";
    return (base / row[column[name]]).string();
  };
  std::vector<ScanJob> jobs;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> row = csv_cells(line);
    const std::string where = "manifest " + path + " line " + std::to_string(n);
    if (row.size() != header.size())
      throw InputError(where + ": " + std::to_string(row.size()) + " cells, the header has " +
                       std::to_string(header.size()));
    ScanJob job{file(row, "scan"), rel_inside(row[column["scan"]]), file(row, "flange_pose"),
                file(row, "hand_eye"), std::nullopt};
    if (job.path.empty()) throw InputError(where + ": no scan");
    if (column.count("viewpoint") && !row[column["viewpoint"]].empty()) {
      job.viewpoint = parse_viewpoint(row[column["viewpoint"]], where);
    }
    jobs.push_back(job);
  }
  return jobs;
}

std::vector<ScanJob> list_jobs(const std::vector<std::string>& inputs, const ListOptions& options) {
  std::vector<ScanJob> jobs;
  for (const std::string& input : inputs) {
    std::error_code ec;
    const fs::path p(input);
    std::vector<ScanJob> found;
    if (fs::is_directory(p, ec)) {
      found = scans_in_directory(p, options);
    } else if (fs::is_regular_file(p, ec) && io::lower_extension(p.string()) == ".csv") {
      found = read_manifest(input);
    } else if (fs::exists(p, ec)) {
      found.push_back({input, without_extension(p.filename()), "", "", std::nullopt});
    } else {
      throw InputError("input " + input + " does not exist");
    }
    jobs.insert(jobs.end(), found.begin(), found.end());
  }
  if (jobs.empty()) {
    throw InputError("no scan (.pcd, .ply, or .png with its intrinsics) in the inputs");
  }
  auto by_dir = [](const ScanJob& a, const ScanJob& b) {
    return a.rel != b.rel ? a.rel < b.rel : a.path < b.path;
  };
  std::stable_sort(jobs.begin(), jobs.end(), by_dir);
  make_unique(jobs);
  std::stable_sort(jobs.begin(), jobs.end(), by_dir);
  return jobs;
}

std::vector<ScanJob> shard(const std::vector<ScanJob>& jobs, int index, int count) {
  std::vector<ScanJob> mine;
  for (std::size_t i = static_cast<std::size_t>(index); i < jobs.size();
       i += static_cast<std::size_t>(count)) {
    mine.push_back(jobs[i]);
  }
  return mine;
}

void parse_shard(const std::string& text, int& index, int& count) {
  const auto slash = text.find('/');
  try {
    std::size_t used_k = 0, used_n = 0;
    if (slash == std::string::npos) throw std::invalid_argument("no slash");
    const int k = std::stoi(text.substr(0, slash), &used_k);
    const int n = std::stoi(text.substr(slash + 1), &used_n);
    if (used_k != slash || used_n != text.size() - slash - 1 || n < 1 || k < 0 || k >= n) {
      throw std::invalid_argument("range");
    }
    index = k;
    count = n;
  } catch (const std::exception&) {
    throw UsageError("--shard: expected K/N with 0 <= K < N, got '" + text + "'");
  }
}

bool shard_from_environment(int count_given, int& index, int& count) {
  // A set variable must hold a non-negative integer.
  auto number = [](const char* name, int& out) {
    const char* v = std::getenv(name);
    if (!v || !*v) return false;
    char* end = nullptr;
    const long n = std::strtol(v, &end, 10);
    if (*end != '\0' || n < 0 || n > 1000000000) {
      throw UsageError(std::string(name) + ": expected a non-negative integer, got '" + v + "'");
    }
    out = static_cast<int>(n);
    return true;
  };
  int id = 0, n = 0, min = 0;
  if (number("SLURM_ARRAY_TASK_ID", id) && number("SLURM_ARRAY_TASK_COUNT", n)) {
    number("SLURM_ARRAY_TASK_MIN", min);
    parse_shard(std::to_string(id - min) + "/" + std::to_string(n), index, count);
    return true;
  }
  if (number("JOB_COMPLETION_INDEX", id)) {
    if (count_given < 1) {
      throw UsageError("JOB_COMPLETION_INDEX is set: give the shard count as --shard-count N");
    }
    parse_shard(std::to_string(id) + "/" + std::to_string(count_given), index, count);
    return true;
  }
  return false;
}

}  // namespace groovetrace::batch
