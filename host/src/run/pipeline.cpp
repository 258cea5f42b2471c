#include <chrono>
#include <cmath>
#include <filesystem>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/frames.hpp>
#include <groovetrace/pipeline.hpp>
#include <groovetrace/trajectory_io.hpp>
#include <groovetrace/urscript.hpp>
#include <nlohmann/json.hpp>

namespace groovetrace {
namespace {

class StageTimer {
 public:
  StageTimer(std::vector<std::pair<std::string, double>>& out, const StageCallback& cb)
      : out_(out), cb_(cb) {}
  void lap(const std::string& stage) {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    out_.emplace_back(stage, ms);
    if (cb_) cb_(stage, ms);
    last_ = now;
  }

 private:
  std::vector<std::pair<std::string, double>>& out_;
  const StageCallback& cb_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

const char* version() { return GROOVETRACE_VERSION; }

void validate(const Params& params) {
  // Re-parsing each value through its spec applies exactly the CLI's range checks to
  // parameters set from code.
  Params scratch = params;
  for (const auto& spec : param_specs()) {
    std::string text = spec.json(params);
    if (text == "null") continue;
    if (text.size() >= 2 && text.front() == '"')
      text = nlohmann::json::parse(text).get<std::string>();
    if (text.size() >= 2 && text.front() == '[') text = text.substr(1, text.size() - 2);
    spec.set(scratch, text);
  }
  if (params.hand_eye_file.empty() != params.flange_pose_file.empty()) {
    throw UsageError("--hand-eye and --flange-pose must be given together");
  }
}

namespace {

// --method robust (docs/method-robust.md). The backend measures the creases; its normals are
// the crease map's plane normals at the groove's scale, its descriptor the concavity (mm).
void run_robust(const Cloud& cloud, const Params& params, FeatureBackend& backend, RunResult& r,
                StageTimer& timer) {
  RobustParams rp;
  rp.step = params.step;
  rp.slices = params.slices_given ? params.slices : 0;
  rp.max_seams = params.max_seams;
  r.smoothed = cloud;
  r.robust = detect_robust(cloud, rp, backend, [&](const std::string& stage) { timer.lap(stage); });
  r.normals = r.robust.normals;
  r.benchmark_normal = benchmark_normal(r.normals);
  r.descriptor.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    r.descriptor[i] = r.robust.concavity[i] * 1000.0f;
  }
  Detection& d = r.detection;
  d.groove = r.robust.groove;
  d.threshold = r.robust.threshold * 1000.0;
  d.above_threshold = r.robust.candidates;
  d.component_label.assign(cloud.size(), -1);
  std::vector<const SeamCandidate*> accepted;
  for (const SeamCandidate& s : r.robust.seams) {
    if (s.accepted) accepted.push_back(&s);
  }
  d.components = accepted.size();
  if (accepted.empty()) {
    std::string why = std::to_string(r.robust.seams.size()) + " candidate seams";
    if (!r.robust.seams.empty()) {
      why += ", none a V-groove (best: " + r.robust.seams.front().reason + ")";
    }
    throw NoGrooveError("no groove found: " + std::to_string(r.robust.candidates) +
                        " concave candidates, " + why);
  }
  for (const SeamCandidate* s : accepted) {
    d.component_sizes.push_back(s->sections.size());
  }
  for (std::size_t k = 0; k < accepted.size() && static_cast<int>(k) < params.max_seams; ++k) {
    Trajectory t = seam_trajectory(*accepted[k], rp);
    if (k == 0) {
      r.trajectory = std::move(t);
    } else {
      r.extra_trajectories.push_back(std::move(t));
    }
  }
  timer.lap("trajectory");
}

}  // namespace

RunResult run_pipeline(const Cloud& input, const Params& params, FeatureBackend& backend,
                       const StageCallback& on_stage) {
  validate(params);
  RunResult r;
  // Named once the stages are done: a backend still being set up (the CLI's) is waited for
  // only when a stage first needs it.
  auto name_backend = [&] {
    r.backend = backend.name();
    r.device = backend.device();
  };
  StageTimer timer(r.timings_ms, on_stage);

  // Calibration files are read first: a typo there should not cost a full run.
  std::optional<Eigen::Isometry3d> T_base_camera;
  if (!params.hand_eye_file.empty()) {
    const Eigen::Isometry3d T_flange_camera = read_transform(params.hand_eye_file);
    const Eigen::Isometry3d T_base_flange = read_transform(params.flange_pose_file);
    T_base_camera = T_base_flange * T_flange_camera;
  }

  Cloud cloud = input;
  if (params.viewpoint) cloud.viewpoint = *params.viewpoint;
  const float radius = static_cast<float>(params.radius);

  if (params.method == "robust") {
    run_robust(cloud, params, backend, r, timer);
    if (T_base_camera) {
      transform_trajectory(r.trajectory, *T_base_camera);
      for (Trajectory& t : r.extra_trajectories) transform_trajectory(t, *T_base_camera);
    }
    name_backend();
    return r;
  }

  if (params.smooth) {
    SmoothParams sp;
    sp.radius = static_cast<float>(params.mls_radius);
    sp.order = params.mls_order;
    sp.min_neighbors = params.min_neighbors;
    r.smoothed = backend.smooth(cloud, sp);
  } else {
    r.smoothed = cloud;
  }
  timer.lap("smooth");

  r.normals = backend.normals(r.smoothed, radius, params.min_neighbors);
  r.benchmark_normal = benchmark_normal(r.normals);
  timer.lap("normals");
  if (!r.benchmark_normal.allFinite()) {
    throw NoGrooveError("no groove found: no point has " + std::to_string(params.min_neighbors) +
                        " neighbours within the radius " + std::to_string(params.radius) +
                        " m (is --units right?)");
  }

  r.descriptor = backend.descriptor(r.smoothed, r.normals, radius, r.benchmark_normal);
  timer.lap("descriptor");

  const float link =
      static_cast<float>(params.link_distance > 0 ? params.link_distance : params.radius);
  r.detection =
      detect_groove(r.smoothed, r.descriptor, params.threshold_auto ? NAN : params.threshold,
                    params.min_component, link);
  timer.lap("detect");
  if (r.detection.components == 0) {
    throw NoGrooveError("no groove found: " + std::to_string(r.detection.above_threshold) +
                        " points above threshold " + std::to_string(r.detection.threshold) +
                        ", no connected part of " + std::to_string(params.min_component) +
                        " or more");
  }
  // The paper slices every point that passed the threshold: a V's two top edges and its
  // root are separate creases, often separate parts, and their median lies between them.
  r.trajectory = paper_trajectory(r.smoothed, r.normals, r.detection.groove, params.slices,
                                  params.median_max_iterations, params.median_tolerance);
  if (T_base_camera) transform_trajectory(r.trajectory, *T_base_camera);
  timer.lap("trajectory");
  name_backend();
  return r;
}

namespace {

// report.json "robust": the candidate threshold and every candidate seam with its score
// (docs/method-robust.md, "Score"), best first; `file` names the trajectory written for it.
nlohmann::json robust_report(const RunResult& result, const Params& params) {
  using nlohmann::json;
  const RobustDetection& rd = result.robust;
  json seams = json::array();
  int exported = 0;
  for (std::size_t k = 0; k < rd.seams.size(); ++k) {
    const SeamCandidate& s = rd.seams[k];
    json file = nullptr;
    if (s.accepted && exported < params.max_seams) {
      file = exported == 0 ? "trajectory.csv" : "trajectory_" + std::to_string(exported) + ".csv";
      ++exported;
    }
    auto num = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
    seams.push_back({{"rank", k},
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
                     {"file", file}});
  }
  return {{"concavity_threshold_m", rd.threshold},
          {"concavity_sigma_m", rd.noise_sigma},
          {"candidate_voxels", rd.candidates},
          {"crease_nodes", rd.nodes},
          {"confirmed_nodes", rd.confirmed_nodes},
          {"score", "length_mm * ok_fraction * fit_quality * consistency"},
          {"seams", seams}};
}

}  // namespace

std::vector<std::pair<std::string, std::string>> render_outputs(const Cloud& input,
                                                                const RunResult& result,
                                                                const Params& params,
                                                                const std::string& input_path,
                                                                double total_ms) {
  using nlohmann::json;
  std::vector<std::pair<std::string, std::string>> files;
  Annotations ann;
  ann.normals = &result.normals;
  ann.descriptor = &result.descriptor;
  ann.groove = &result.detection.groove;
  files.emplace_back("annotated.pcd", annotated_pcd_bytes(input, ann));
  files.emplace_back("trajectory.csv", trajectory_csv(result.trajectory));
  files.emplace_back("trajectory.json", trajectory_json(result.trajectory, params));
  files.emplace_back("program.script", urscript_program(result.trajectory, params));
  for (std::size_t k = 0; k < result.extra_trajectories.size(); ++k) {
    const std::string n = std::to_string(k + 1);
    const Trajectory& t = result.extra_trajectories[k];
    files.emplace_back("trajectory_" + n + ".csv", trajectory_csv(t));
    files.emplace_back("trajectory_" + n + ".json", trajectory_json(t, params));
    files.emplace_back("program_" + n + ".script", urscript_program(t, params));
  }

  std::size_t with_normal = 0, groove = 0;
  for (std::size_t i = 0; i < result.normals.size(); ++i) {
    with_normal += result.normals.valid(i) ? 1 : 0;
    groove += result.detection.groove[i];
  }
  json timings = json::object();
  for (const auto& [stage, ms] : result.timings_ms) timings[stage] = ms;
  timings["total"] = total_ms;
  const Eigen::Vector3f& ub = result.benchmark_normal;
  json report = {{"version", version()},
                 {"input", input_path},
                 {"method", params.method},
                 {"backend", result.backend},
                 {"device", result.device},
                 {"parameters", json::parse(params_json(params))},
                 {"points",
                  {{"total", input.size()},
                   {"width", input.width},
                   {"height", input.height},
                   {"valid", input.count_valid()},
                   {"with_normal", with_normal},
                   {"above_threshold", result.detection.above_threshold},
                   {"groove", groove}}},
                 {"detection",
                  {{"threshold_deg2",
                    params.method == "robust" ? json(nullptr) : json(result.detection.threshold)},
                   {"threshold_mode", params.method == "robust" ? "robust_concavity_mm"
                                      : params.threshold_auto   ? "otsu_log_descriptor"
                                                                : "fixed"},
                   {"components", result.detection.components},
                   {"component_sizes", result.detection.component_sizes},
                   {"benchmark_normal", {ub.x(), ub.y(), ub.z()}}}},
                 {"trajectory",
                  {{"frame", result.trajectory.frame},
                   {"waypoints", result.trajectory.waypoints.size()},
                   {"length_m", result.trajectory.length}}},
                 {"timings_ms", timings},
                 {"warnings", result.warnings}};
  if (params.method == "robust") report["robust"] = robust_report(result, params);
  files.emplace_back("report.json", report.dump(2) + "\n");
  return files;
}

void write_outputs(const std::string& out_dir,
                   const std::vector<std::pair<std::string, std::string>>& files) {
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec || !std::filesystem::is_directory(out_dir)) {
    throw InputError("cannot create output directory " + out_dir +
                     (ec ? ": " + ec.message() : ": not a directory"));
  }
  for (const auto& [name, bytes] : files) {
    write_file_atomic((std::filesystem::path(out_dir) / name).string(), bytes);
  }
}

}  // namespace groovetrace
