// Reading a `groovetrace run` output directory for evaluation: annotated.pcd (the detection),
// trajectory.csv (the poses), and, when present, trajectory.json (frame) and report.json
// (timings).

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <groovetrace/error.hpp>
#include <groovetrace/eval.hpp>
#include <iterator>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "io/pcd.hpp"

namespace groovetrace {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool read_file(const std::string& path, std::string& bytes) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return true;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::string item;
  std::istringstream in(s);
  while (std::getline(in, item, sep)) out.push_back(item);
  return out;
}

// annotated.pcd's `groove` field as 0/1 flags, plus its WIDTH and HEIGHT, through the PCD
// reader that checks scans (any DATA kind).
std::vector<std::uint8_t> read_groove_flags(const std::string& path, std::uint32_t& width,
                                            std::uint32_t& height) {
  io::PcdTable table;
  try {
    table = io::read_pcd_fields(path, {"groove"});
  } catch (const InputError& e) {
    throw InputError(std::string("eval: ") + e.what());
  }
  width = table.width;
  height = table.height;
  const std::vector<float>& groove = *table.column("groove");
  std::vector<std::uint8_t> flags(groove.size());
  for (std::size_t i = 0; i < groove.size(); ++i) flags[i] = groove[i] != 0.0f ? 1 : 0;
  return flags;
}

std::vector<ToolPose> read_trajectory_csv(const std::string& path) {
  std::string bytes;
  if (!read_file(path, bytes)) throw InputError("eval: cannot read " + path);
  std::istringstream in(bytes);
  std::string line;
  if (!std::getline(in, line)) throw InputError("eval: " + path + " is empty");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const std::vector<std::string> head = split(line, ',');
  const char* names[] = {"x_m", "y_m", "z_m", "qx", "qy", "qz", "qw"};
  int col[7];
  for (int k = 0; k < 7; ++k) {
    col[k] = -1;
    for (std::size_t c = 0; c < head.size(); ++c)
      if (head[c] == names[k]) col[k] = static_cast<int>(c);
    if (col[k] < 0) throw InputError("eval: " + path + " has no column " + names[k]);
  }
  std::vector<ToolPose> poses;
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::vector<std::string> cells = split(line, ',');
    double v[7];
    for (int k = 0; k < 7; ++k) {
      char* end = nullptr;
      const char* s = static_cast<std::size_t>(col[k]) < cells.size() ? cells[col[k]].c_str() : "";
      v[k] = std::strtod(s, &end);
      if (end == s || !std::isfinite(v[k]))
        throw InputError("eval: " + path + " line " + std::to_string(row) + ": bad " + names[k]);
    }
    ToolPose p;
    p.position = {v[0], v[1], v[2]};
    p.orientation = Eigen::Quaterniond(v[6], v[3], v[4], v[5]).normalized();
    poses.push_back(p);
  }
  return poses;
}

// report.json is the run's business; accept the shapes a report plausibly has: a top-level
// "total_ms", and stage timings as {"name": ms} or [{"name"/"stage": .., "ms": ..}] under a
// key containing "timing" or "stage".
void read_report(const nlohmann::json& j, RunOutput& out) {
  using nlohmann::json;
  if (!j.is_object()) return;
  for (const char* key : {"total_ms", "end_to_end_ms", "wall_ms"})
    if (j.contains(key) && j[key].is_number()) out.total_ms = j[key].get<double>();
  for (const auto& [key, value] : j.items()) {
    if (key.find("timing") == std::string::npos && key.find("stage") == std::string::npos) continue;
    if (value.is_object()) {
      for (const auto& [name, ms] : value.items()) {
        if (!ms.is_number()) continue;
        if (name == "total" || name == "total_ms")
          out.total_ms = ms.get<double>();
        else
          out.stage_ms.emplace_back(name, ms.get<double>());
      }
    } else if (value.is_array()) {
      for (const json& e : value) {
        if (!e.is_object() || !e.contains("ms") || !e["ms"].is_number()) continue;
        const std::string name = e.contains("name")    ? e["name"].get<std::string>()
                                 : e.contains("stage") ? e["stage"].get<std::string>()
                                                       : "?";
        if (name == "total")
          out.total_ms = e["ms"].get<double>();
        else
          out.stage_ms.emplace_back(name, e["ms"].get<double>());
      }
    }
  }
}

// The joint and tacks the detector reports for the first exported seam: the robust.seams
// entry whose "file" is "trajectory.csv". Tacks without a finite position and length are
// skipped.
void read_report_seam(const nlohmann::json& j, RunOutput& out) {
  if (!j.is_object() || !j.contains("robust") || !j["robust"].is_object()) return;
  const nlohmann::json& robust = j["robust"];
  if (!robust.contains("seams") || !robust["seams"].is_array()) return;
  for (const nlohmann::json& seam : robust["seams"]) {
    if (!seam.is_object() || !seam.contains("file") || seam["file"] != "trajectory.csv") continue;
    if (seam.contains("joint") && seam["joint"].is_string())
      out.joint = seam["joint"].get<std::string>();
    if (!seam.contains("tacks") || !seam["tacks"].is_array()) return;
    out.has_tacks = true;
    for (const nlohmann::json& t : seam["tacks"]) {
      if (!t.is_object() || !t.contains("position_m") || !t["position_m"].is_number() ||
          !t.contains("length_m") || !t["length_m"].is_number())
        continue;
      out.tacks.push_back({t["position_m"].get<double>(), t["length_m"].get<double>()});
    }
    return;
  }
}

}  // namespace

RunOutput read_run_output(const std::string& result_dir) {
  RunOutput out;
  out.total_ms = kNaN;
  const std::string dir =
      result_dir.empty() || result_dir.back() == '/' ? result_dir : result_dir + "/";
  out.groove = read_groove_flags(dir + "annotated.pcd", out.width, out.height);

  std::string bytes;
  if (read_file(dir + "trajectory.csv", bytes)) {
    out.poses = read_trajectory_csv(dir + "trajectory.csv");
    out.has_trajectory = true;
    out.trajectories.emplace_back("trajectory.csv", out.poses);
    for (int k = 1; read_file(dir + "trajectory_" + std::to_string(k) + ".csv", bytes); ++k) {
      const std::string name = "trajectory_" + std::to_string(k) + ".csv";
      out.trajectories.emplace_back(name, read_trajectory_csv(dir + name));
    }
  }
  if (read_file(dir + "trajectory.json", bytes)) {
    const nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
    if (j.is_object() && j.contains("frame") && j["frame"].is_string())
      out.frame = j["frame"].get<std::string>();
  }
  if (read_file(dir + "report.json", bytes)) {
    const nlohmann::json j = nlohmann::json::parse(bytes, nullptr, false);
    if (!j.is_discarded()) {
      read_report(j, out);
      read_report_seam(j, out);
    }
  }
  return out;
}

EvalMetrics evaluate_files(const std::string& scan_path, const std::string& result_dir,
                           const EvalOptions& options) {
  const SynthTruth truth = read_synth_truth(scan_path);
  const RunOutput run = read_run_output(result_dir);
  if (run.groove.size() != truth.label.size() ||
      run.width != static_cast<std::uint32_t>(truth.camera.width))
    throw InputError("eval: " + result_dir + "/annotated.pcd has " + std::to_string(run.width) +
                     "x" + std::to_string(run.height) + " points, the scan " +
                     std::to_string(truth.camera.width) + "x" +
                     std::to_string(truth.camera.height));
  EvalMetrics m = evaluate(truth, run.groove, run.poses, options);
  if (!run.has_trajectory) m.notes.push_back("no trajectory.csv: trajectory metrics undefined");
  if (run.frame != "camera")
    m.notes.push_back("the trajectory is in frame '" + run.frame +
                      "', eval assumes the scan's camera frame: trajectory metrics are wrong");
  double total = run.total_ms;
  if (!std::isfinite(total) && !run.stage_ms.empty()) {
    total = 0.0;
    for (const auto& stage : run.stage_ms) total += stage.second;
    m.notes.push_back("runtime is the sum of the reported stages");
  }
  m.runtime_ms = total;
  m.points_per_second =
      std::isfinite(total) && total > 0.0 ? static_cast<double>(m.points) / (total * 1e-3) : kNaN;
  m.stage_ms = run.stage_ms;
  m.joint_found = run.joint;
  m.seam_scores = score_seams(truth, run.trajectories, options);
  m.tacks = score_tacks(truth, run.poses, run.tacks, options);
  m.tacks.reported = run.has_tacks;
  return m;
}

}  // namespace groovetrace
