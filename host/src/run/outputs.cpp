// The files of a run: annotated cloud, overview picture, trajectories, robot programs and
// report.json, rendered as bytes first and then written as one set (io/output_dir.hpp).

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>
#include <groovetrace/program.hpp>
#include <groovetrace/trajectory_io.hpp>
#include <groovetrace/version.hpp>
#include <nlohmann/json.hpp>
#include <regex>

#include "io/output_dir.hpp"
#include "picture/overview.hpp"
#include "run/overview.hpp"

namespace groovetrace {
namespace {

using nlohmann::json;

json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

// The fitted cross-section at every station of a seam, in the trajectory's order
// (docs/method-robust.md, "Score"): arc length along the path and root (m, the cloud's frame),
// opening width, depth, included angle, high-low, and how the station was fitted.
json stations_json(const SeamCandidate& seam) {
  auto num = finite_or_null;
  std::vector<std::pair<double, const GrooveSection*>> order;
  for (const GrooveSection& s : seam.sections) order.emplace_back(travel_arc(seam, s.s), &s);
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  json out = json::array();
  for (const auto& [along, sec] : order) {
    const GrooveSection& s = *sec;
    const char* fit = !s.ok        ? (s.inferred   ? "inferred"
                                      : s.extended ? "extended"
                                                   : "none")
                      : s.corner   ? "corner"
                      : s.one_wall ? "one_wall"
                                   : "v";
    out.push_back(
        {{"s_m", num(along)},
         {"root_m", {num(s.root.x()), num(s.root.y()), num(s.root.z())}},
         {"opening_m", num(s.width)},
         {"depth_m", num(s.depth)},
         {"included_angle_deg", s.ok ? num(s.opening_deg) : json(nullptr)},
         {"misalignment_m",
          s.ok && !s.one_wall && !s.corner ? num(std::abs(s.misalignment)) : json(nullptr)},
         {"gap_m", s.ok && !s.one_wall && !s.corner ? num(s.gap) : json(nullptr)},
         {"fit", fit}});
  }
  return out;
}

// The tack welds found along a seam, in the trajectory's order: arc length of each one's centre
// along the path (as the stations') and its length (m).
json tacks_json(const SeamCandidate& seam) {
  std::vector<std::pair<double, double>> tacks;  // (along the path, length)
  for (const SeamCandidate::Tack& t : seam.tacks)
    tacks.emplace_back(travel_arc(seam, t.position), t.length);
  std::sort(tacks.begin(), tacks.end());
  json out = json::array();
  for (const auto& [along, length] : tacks)
    out.push_back({{"position_m", finite_or_null(along)}, {"length_m", finite_or_null(length)}});
  return out;
}

// The fastest turn of the torch along `t` (deg/mm) and where (arc length, m); null without a
// trajectory.
void add_rotation_rate(json& j, const Trajectory* t) {
  const RotationRate r = t ? max_rotation_rate(*t) : RotationRate{};
  j["max_rotation_deg_per_mm"] = t ? finite_or_null(r.deg_per_mm) : json(nullptr);
  j["max_rotation_at_m"] = t ? finite_or_null(r.at_m) : json(nullptr);
}

json seam_json(const SeamCandidate& s, std::size_t rank, const json& file, const Trajectory* t) {
  auto num = finite_or_null;
  json j = {{"rank", rank},
            {"accepted", s.accepted},
            {"reason", s.reason},
            {"score", num(s.score)},
            {"length_m", num(s.length)},
            {"closed", s.closed},
            {"corners", s.curve.corners.size()},
            {"sections", s.sections.size()},
            {"ok_fraction", num(s.ok_fraction)},
            {"fit_quality", num(s.fit_quality)},
            {"consistency", num(s.consistency)},
            {"width_m", num(s.width)},
            {"depth_m", num(s.depth)},
            {"opening_deg", num(s.opening_deg)},
            {"joint", s.joint},
            {"misalignment_m", num(s.misalignment)},
            {"gap_m", s.corner ? json(nullptr) : num(s.gap)},
            {"scale_m", num(s.scale)},
            {"tacks", tacks_json(s)},
            {"file", file}};
  if (!file.is_null()) j["stations"] = stations_json(s);
  add_rotation_rate(j, t);
  return j;
}

// report.json "robust": the candidate threshold and every candidate seam with its score
// (docs/method-robust.md, "Score"), best first; `file` names the trajectory written for it
// (`trajectories`, in that order), whose fastest turn is reported with it.
json robust_report(const RobustDetection& rd, const std::vector<Trajectory>& trajectories,
                   int max_seams) {
  json seams = json::array();
  const std::vector<bool> written = exported_seams(rd.seams, max_seams);
  int exported = 0;
  for (std::size_t k = 0; k < rd.seams.size(); ++k) {
    const SeamCandidate& s = rd.seams[k];
    json file = nullptr;
    const Trajectory* t = nullptr;
    if (written[k]) {
      file = exported == 0 ? "trajectory.csv" : "trajectory_" + std::to_string(exported) + ".csv";
      const auto e = static_cast<std::size_t>(exported);
      t = e < trajectories.size() ? &trajectories[e] : nullptr;
      ++exported;
    }
    seams.push_back(seam_json(s, k, file, t));
  }
  json scales = json::array();
  for (const ScaleSearchSummary& sc : rd.scales) {
    scales.push_back({{"scale_m", sc.scale},
                      {"cell_m", sc.cell},
                      {"concavity_threshold_m", sc.threshold},
                      {"candidate_voxels", sc.candidates},
                      {"crease_nodes", sc.nodes},
                      {"confirmed_nodes", sc.confirmed_nodes},
                      {"seams", sc.seams},
                      {"kept", sc.kept}});
  }
  return {{"concavity_threshold_m", rd.threshold},
          {"concavity_sigma_m", rd.noise_sigma},
          {"threshold_k", rd.threshold_k},
          {"retried", rd.retried},
          {"candidate_voxels", rd.candidates},
          {"crease_nodes", rd.nodes},
          {"confirmed_nodes", rd.confirmed_nodes},
          {"score", "length_mm * ok_fraction * fit_quality * consistency"},
          {"scales", scales},
          {"seams", seams}};
}

// report.json "detection". Robust: components are the accepted seams, their sizes the
// sections (stations) of each; paper: the kept connected parts and their point counts.
json detection_report(const RunResult& result, const Params& params) {
  const Eigen::Vector3f ub = benchmark_normal(result.normals);
  json d = {{"threshold_deg2", nullptr}, {"threshold_mode", "robust_concavity_mm"}};
  if (result.method == Method::paper) {
    const Detection& pd = result.paper.detection;
    d["threshold_deg2"] = pd.threshold;
    d["threshold_mode"] = params.paper.threshold_auto ? "otsu_log_descriptor" : "fixed";
    d["components"] = pd.components;
    d["component_sizes"] = pd.component_sizes;
  } else {
    std::vector<std::size_t> sizes;
    for (const SeamCandidate& s : result.robust.seams) {
      if (s.accepted) sizes.push_back(s.sections.size());
    }
    d["components"] = sizes.size();
    d["component_sizes"] = sizes;
  }
  d["seams_found"] = result.seams_found;
  d["seams_exported"] = result.trajectories.size();
  d["benchmark_normal"] = {ub.x(), ub.y(), ub.z()};
  return d;
}

json points_report(const Cloud& input, const RunResult& result) {
  std::size_t with_normal = 0, groove = 0;
  for (std::size_t i = 0; i < result.normals.size(); ++i) {
    with_normal += result.normals.valid(i) ? 1 : 0;
    groove += result.groove[i];
  }
  const std::size_t above = result.method == Method::paper ? result.paper.detection.above_threshold
                                                           : result.robust.candidates;
  return {{"total", input.size()},
          {"width", input.width},
          {"height", input.height},
          {"valid", input.count_valid()},
          {"with_normal", with_normal},
          {"above_threshold", above},
          {"groove", groove}};
}

// report.json "programs": per exported seam, its program file (null when none is written: the
// poses are camera coordinates) and its passes in weld order.
json programs_json(const RunResult& result,
                   const std::vector<std::pair<std::string, std::string>>& files) {
  json out = json::array();
  for (std::size_t k = 0; k < result.passes.size(); ++k) {
    // The program's file for --robot (program.script, .mod, or .src beside its .dat).
    const std::string stem = k == 0 ? "program." : "program_" + std::to_string(k) + ".";
    const auto file = std::find_if(files.begin(), files.end(), [&](const auto& f) {
      return f.first.rfind(stem, 0) == 0 && f.first.find(".dat") == std::string::npos;
    });
    json passes = json::array();
    for (const WeldPass& p : result.passes[k]) {
      passes.push_back(
          {{"name", p.name}, {"waypoints", p.path.waypoints.size()}, {"length_m", p.path.length}});
    }
    out.push_back(
        {{"file", file != files.end() ? json(file->first) : json(nullptr)}, {"passes", passes}});
  }
  return out;
}

// report.json "outputs": the other files of the set with their sizes, so a reader can tell
// that the files beside it are the ones this run wrote.
json outputs_json(const std::vector<std::pair<std::string, std::string>>& files) {
  json out = json::array();
  for (const auto& [name, bytes] : files) out.push_back({{"file", name}, {"bytes", bytes.size()}});
  return out;
}

std::string report_json(const Cloud& input, const RunResult& result, const Params& params,
                        const std::string& input_path, double total_ms,
                        const std::vector<std::pair<std::string, std::string>>& files) {
  json timings = json::object();
  for (const auto& [stage, ms] : result.timings_ms) timings[stage] = ms;
  timings["total"] = total_ms;
  const Trajectory& best = result.trajectories.front();
  json trajectory = {
      {"frame", best.frame}, {"waypoints", best.waypoints.size()}, {"length_m", best.length}};
  add_rotation_rate(trajectory, &best);
  json report = {{"version", version()},
                 {"input", input_path},
                 {"status", status_name(ExitCode::kOk)},
                 {"exit_code", 0},
                 {"outputs", outputs_json(files)},
                 {"method", to_string(result.method)},
                 {"backend", result.backend},
                 {"device", result.device},
                 {"parameters", json::parse(params_json(params))},
                 {"points", points_report(input, result)},
                 {"detection", detection_report(result, params)},
                 {"trajectory", trajectory},
                 {"programs", programs_json(result, files)},
                 {"timings_ms", timings},
                 {"warnings", result.warnings}};
  if (result.method == Method::robust) {
    report["robust"] = robust_report(result.robust, result.trajectories, params.robust.max_seams);
  }
  return report.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace

// overview.png, drawn in the scan's frame: trajectories moved into the base are moved back.
std::string run_overview_png(const Cloud& input, const RunResult& result, const Params& params,
                             const std::string& input_path, int max_side) {
  picture::OverviewInput in(input, result.groove, result.trajectories);
  if (result.T_base_camera) in.T_cloud_trajectory = result.T_base_camera->inverse();
  in.viewpoint = params.viewpoint;
  const std::size_t n = result.warnings.size();
  const std::string status =
      n == 0 ? "ok" : std::to_string(n) + (n == 1 ? " warning" : " warnings");
  in.caption = picture::caption_line(std::filesystem::path(input_path).filename().string(),
                                     to_string(result.method), result.trajectories, status);
  return picture::overview_png(in, max_side);
}

std::vector<std::pair<std::string, std::string>> render_outputs(const Cloud& input,
                                                                const RunResult& result,
                                                                const Params& params,
                                                                const std::string& input_path,
                                                                double total_ms) {
  if (result.trajectories.empty()) throw InternalError("render_outputs: no trajectory");
  std::vector<std::pair<std::string, std::string>> files;
  Annotations ann;
  ann.normals = &result.normals;
  ann.descriptor = &result.score;
  ann.groove = &result.groove;
  files.emplace_back("annotated.pcd", annotated_pcd_bytes(input, ann));
  files.emplace_back("overview.png", run_overview_png(input, result, params, input_path, 0));
  for (std::size_t k = 0; k < result.trajectories.size(); ++k) {
    const std::string n = k == 0 ? "" : "_" + std::to_string(k);
    const Trajectory& t = result.trajectories[k];
    files.emplace_back("trajectory" + n + ".csv", trajectory_csv(t));
    files.emplace_back("trajectory" + n + ".json", trajectory_json(t, params));
    files.emplace_back("trajectory" + n + ".ros.yaml", trajectory_ros_yaml(t));
    if (result.programs) {
      for (auto& file : program_files(result.passes[k], params.program, "program" + n)) {
        files.push_back(std::move(file));
      }
    }
  }
  files.emplace_back("report.json",
                     report_json(input, result, params, input_path, total_ms, files));
  return files;
}

bool is_run_output(const std::string& name) {
  // The files render_outputs and write_failure_report make, eval's metrics.json (it scores
  // them), and the temporaries of an earlier version's per-file writes (.NAME.XXXXXXXX.tmp).
  static const std::regex kOutput(
      R"(annotated\.pcd|overview\.png|report\.json|metrics\.json|)"
      R"(trajectory(_[0-9]+)?\.(csv|json|ros\.yaml)|program(_[0-9]+)?\.(script|mod|src|dat)|)"
      R"(\..+\.[A-Za-z0-9]{8}\.tmp)");
  return std::regex_match(name, kOutput);
}

void check_output_dir(const std::string& out_dir) {
  // An empty path has no absolute form (std::filesystem threw: exit 5, "internal").
  if (out_dir.empty()) throw UsageError("-o: the output directory is an empty path");
  io::check_replaceable(out_dir, is_run_output);
}

void write_outputs(const std::string& out_dir,
                   const std::vector<std::pair<std::string, std::string>>& files) {
  io::replace_directory(out_dir, files, is_run_output);
}

namespace {

// Programs first: a reader that looks in between finds no program.
void remove_outputs(const std::string& out_dir) noexcept {
  std::error_code ec;
  for (const char* first : {"program", ""}) {
    try {
      for (const auto& e : std::filesystem::directory_iterator(out_dir, ec)) {
        const std::string name = e.path().filename().string();
        if (is_run_output(name) && name.rfind(first, 0) == 0) std::filesystem::remove(e.path(), ec);
      }
    } catch (...) {  // an entry that vanished while we listed: the next pass sees the rest
    }
  }
}

}  // namespace

void write_failure_report(const std::string& out_dir, const std::string& input_path, ExitCode code,
                          const std::string& message) {
  const json report = {{"version", version()},        {"input", input_path},
                       {"status", status_name(code)}, {"exit_code", static_cast<int>(code)},
                       {"message", message},          {"outputs", json::array()}};
  try {
    // Replaced, not refused: a path's bytes that are not UTF-8 must not cost the report.
    const std::string text = report.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
    write_outputs(out_dir, {{"report.json", text}});
  } catch (...) {
    // No room even for the report (a full disk): at least no earlier program stays behind
    // to be run as this run's.
    remove_outputs(out_dir);
  }
}

}  // namespace groovetrace
