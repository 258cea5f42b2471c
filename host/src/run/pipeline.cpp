// `run_pipeline`: reads the calibration, runs the chosen method and moves its trajectories into
// the base frame. Each method fills RunResult's shared fields and its own detail.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/frames.hpp>
#include <groovetrace/guards.hpp>
#include <groovetrace/pipeline.hpp>
#include <groovetrace/weld.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "run/plausibility.hpp"

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

std::string no_robust_groove(const RobustDetection& rd) {
  std::string why = std::to_string(rd.seams.size()) + " candidate seams";
  if (!rd.seams.empty()) why += ", none a V-groove (best: " + rd.seams.front().reason + ")";
  // Where the search stopped, per scale: a groove with nodes but none confirmed failed its
  // cross-section fit, one without candidates never stood out of the surface.
  std::string per_scale;
  for (const ScaleSearchSummary& s : rd.scales) {
    per_scale += per_scale.empty() ? "" : ", ";
    per_scale += std::to_string(static_cast<int>(std::lround(s.scale * 1000))) + " mm " +
                 std::to_string(s.candidates) + "/" + std::to_string(s.nodes) + "/" +
                 std::to_string(s.confirmed_nodes);
  }
  if (!per_scale.empty()) why += " (candidates/nodes/confirmed per scale: " + per_scale + ")";
  if (rd.retried) why += "; searched again with a lower threshold: none either";
  return "no groove found: " + std::to_string(rd.candidates) + " concave candidates, " + why;
}

// --method robust (docs/method-robust.md). The backend measures the creases; the normals are
// the crease map's plane normals at the groove's scale, the score the concavity (mm).
void run_robust(const Cloud& cloud, const Params& params, FeatureBackend& backend, RunResult& r,
                StageTimer& timer) {
  const RobustParams& rp = params.robust;
  r.robust = detect_robust(cloud, rp, backend, [&](const std::string& stage) { timer.lap(stage); });
  r.normals = r.robust.normals;
  r.groove = r.robust.groove;
  r.score.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) r.score[i] = r.robust.concavity[i] * 1000.0f;
  r.score_unit = "mm";
  const std::vector<bool> exported = exported_seams(r.robust.seams, rp.max_seams);
  for (std::size_t k = 0; k < r.robust.seams.size(); ++k) {
    const SeamCandidate& s = r.robust.seams[k];
    r.seams_found += s.accepted;
    if (!exported[k]) continue;
    r.trajectories.push_back(seam_trajectory(s, rp));
    // The fitted sections are only read by multi-pass planning and the weave's bound.
    const bool sections = params.weld.multi_pass || params.weld.weave != "none";
    r.passes.push_back(weld_passes(
        r.trajectories.back(),
        sections ? section_shapes(r.trajectories.back(), s) : std::vector<SectionShape>{},
        params.weld, params.program, r.warnings));
  }
  if (r.trajectories.empty()) throw NoGrooveError(no_robust_groove(r.robust));
  timer.lap("trajectory");
}

// The paper method's stages visit every neighbour within the radius of every point, so their
// cost grows with the square of the points per neighbourhood: 28,800 identical points took
// 20-46 s, a crop with --radius 0.1 four minutes. Points sharing a radius-sized cell (a
// fraction of the ball) are counted first, and a scan denser than this is refused.
constexpr double kMaxPointsPerCell = 2000;

void require_affordable(const Cloud& cloud, double radius) {
  std::unordered_map<std::uint64_t, std::uint32_t> cells;
  std::size_t valid = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.valid(i)) continue;
    ++valid;
    // Coordinates lie within kMaxCoordinate (require_in_range), so a cell index fits an int64
    // (a negative double cast straight to an unsigned integer is undefined); 21 bits per axis
    // hold any cell of a millimetre or more, and wrapping beyond only merges far cells, which
    // overcounts.
    std::uint64_t key = 0;
    for (const float c : {cloud.x[i], cloud.y[i], cloud.z[i]}) {
      const auto cell = static_cast<std::int64_t>(std::floor(c / radius));
      key = (key << 21) ^ (static_cast<std::uint64_t>(cell) & 0x1FFFFF);
    }
    ++cells[key];
  }
  double pairs = 0;
  for (const auto& [key, n] : cells) pairs += static_cast<double>(n) * n;
  const double per_cell = valid > 0 ? pairs / static_cast<double>(valid) : 0.0;
  if (per_cell > kMaxPointsPerCell) {
    std::ostringstream msg;
    msg << "the scan is too dense for the paper method at radius " << radius
        << " m: " << static_cast<long long>(per_cell)
        << " points share a point's radius-sized cell on "
        << "average (at most " << kMaxPointsPerCell << "); lower --radius or thin the scan";
    throw InputError(msg.str());
  }
}

Cloud paper_smoothed(const Cloud& cloud, const PaperParams& pp, FeatureBackend& backend) {
  if (!pp.smooth) return cloud;
  SmoothParams sp;
  sp.radius = static_cast<float>(pp.mls_radius);
  sp.order = pp.mls_order;
  sp.min_neighbors = pp.min_neighbors;
  return backend.smooth(cloud, sp);
}

// --method paper, as published: MLS, normals, the descriptor D, threshold and components, and
// the trajectory of slices through every point that passed.
void run_paper(const Cloud& cloud, const Params& params, FeatureBackend& backend, RunResult& r,
               StageTimer& timer) {
  const PaperParams& pp = params.paper;
  const float radius = static_cast<float>(pp.radius);
  require_in_range(cloud);
  require_affordable(cloud, std::max(pp.radius, pp.smooth ? pp.mls_radius : 0.0));
  const Cloud& smoothed = r.paper.smoothed = paper_smoothed(cloud, pp, backend);
  timer.lap("smooth");
  r.normals = backend.normals(smoothed, radius, pp.min_neighbors);
  const Eigen::Vector3f u_b = benchmark_normal(r.normals);
  timer.lap("normals");
  if (!u_b.allFinite()) {
    throw NoGrooveError("no groove found: no point has " + std::to_string(pp.min_neighbors) +
                        " neighbours within the radius " + std::to_string(pp.radius) +
                        " m (is --units right?)");
  }
  r.score = backend.descriptor(smoothed, r.normals, radius, u_b);
  r.score_unit = "deg^2";
  timer.lap("descriptor");

  const float link = static_cast<float>(pp.link_distance > 0 ? pp.link_distance : pp.radius);
  const Detection& d = r.paper.detection = detect_groove(
      smoothed, r.score, pp.threshold_auto ? NAN : pp.threshold, pp.min_component, link);
  r.groove = d.groove;
  timer.lap("detect");
  if (d.components == 0) {
    throw NoGrooveError("no groove found: " + std::to_string(d.above_threshold) +
                        " points above threshold " + std::to_string(d.threshold) +
                        ", no connected part of " + std::to_string(pp.min_component) + " or more");
  }
  // The paper slices every point that passed the threshold: a V's two top edges and its
  // root are separate creases, often separate parts, and their median lies between them.
  r.trajectories.push_back(paper_trajectory(smoothed, r.normals, d.groove, pp.slices,
                                            pp.median_max_iterations, pp.median_tolerance));
  r.seams_found = 1;
  r.passes.push_back(
      weld_passes(r.trajectories.back(), {}, params.weld, params.program, r.warnings));
  timer.lap("trajectory");
}

// Without calibration files the poses are camera coordinates, which a robot would take for base
// coordinates: no program unless asked for. Every program to be written passes the guards.
void guard_programs(const Cloud& cloud, const Params& params, RunResult& r) {
  if (r.seams_found > r.trajectories.size()) {
    r.warnings.push_back(std::to_string(r.seams_found) + " seams found, " +
                         std::to_string(r.trajectories.size()) + " exported; --max-seams " +
                         std::to_string(r.seams_found) + " exports them all");
  }
  r.programs = r.T_base_camera.has_value() || params.guards.camera_frame_program;
  if (!r.T_base_camera) {
    r.warnings.push_back(
        r.programs ? "the robot program is in camera coordinates (--camera-frame-program): "
                     "no --hand-eye and --flange-pose were given"
                   : "no robot program written: the trajectory is in camera coordinates "
                     "(give --hand-eye and --flange-pose, or --camera-frame-program)");
  }
  if (!r.programs) return;
  const Eigen::Vector3d viewpoint_camera = cloud.viewpoint.cast<double>();
  const Eigen::Vector3d viewpoint =
      r.T_base_camera ? Eigen::Vector3d(*r.T_base_camera * viewpoint_camera) : viewpoint_camera;
  for (const auto& passes : r.passes)
    check_program(passes, params.guards, params.program, viewpoint);
}

// T_base_camera = T_base_flange * T_flange_camera. An eye-on-base calibration (easy_handeye
// says so) is already T_base_camera: with a real flange pose it would be applied twice.
Eigen::Isometry3d read_T_base_camera(const Params& params) {
  const Calibration hand_eye = read_calibration(params.hand_eye_file);
  const Eigen::Isometry3d T_base_flange = read_transform(params.flange_pose_file);
  if (hand_eye.eye_on_hand == false && !T_base_flange.isApprox(Eigen::Isometry3d::Identity())) {
    throw InputError(params.hand_eye_file +
                     ": an eye-on-base calibration (T_base_camera) given with a flange pose that "
                     "is not the identity; for a camera fixed in the cell give an identity "
                     "--flange-pose (docs/frames.md)");
  }
  return T_base_flange * hand_eye.transform;
}

}  // namespace

void validate(const Params& params) {
  // Re-parsing each value through its spec applies exactly the CLI's range checks to
  // parameters set from code.
  Params scratch = params;
  for (const auto& spec : param_specs()) {
    std::string text = spec.json(params);
    // Only an optional parameter is unset as null; a number's null is a non-finite value set
    // from code, which its spec refuses.
    if (text == "null" && spec.unset) continue;
    if (text.size() >= 2 && text.front() == '"')
      text = nlohmann::json::parse(text).get<std::string>();
    if (text.size() >= 2 && text.front() == '[') text = text.substr(1, text.size() - 2);
    spec.set(scratch, text);
  }
  if (params.robust.slices != 0 && params.robust.slices < 2) {
    throw UsageError("slices: " + std::to_string(params.robust.slices) +
                     " is out of range [2, 100000]");
  }
  if (params.hand_eye_file.empty() != params.flange_pose_file.empty()) {
    throw UsageError("--hand-eye and --flange-pose must be given together");
  }
  if (params.guards.workspace && params.hand_eye_file.empty()) {
    throw UsageError(
        "--workspace is a box of the robot's base frame: it needs --hand-eye and "
        "--flange-pose");
  }
}

RunResult run_pipeline(const Cloud& input, const Params& params, FeatureBackend& backend,
                       const StageCallback& on_stage) {
  validate(params);
  RunResult r;
  r.method = params.method;
  StageTimer timer(r.timings_ms, on_stage);

  // Calibration files are read first: a typo there should not cost a full run.
  std::optional<Eigen::Isometry3d> T_base_camera;
  if (!params.hand_eye_file.empty()) T_base_camera = read_T_base_camera(params);

  Cloud cloud = input;
  if (params.viewpoint) cloud.viewpoint = *params.viewpoint;
  if (params.method == Method::robust) {
    run_robust(cloud, params, backend, r, timer);
  } else {
    run_paper(cloud, params, backend, r, timer);
  }
  for (const std::string& w : plausibility_warnings(cloud, r)) r.warnings.push_back(w);
  if (T_base_camera) {
    for (Trajectory& t : r.trajectories) transform_trajectory(t, *T_base_camera);
    for (auto& passes : r.passes) {
      for (WeldPass& p : passes) transform_trajectory(p.path, *T_base_camera);
    }
    r.T_base_camera = T_base_camera;
  }
  guard_programs(cloud, params, r);
  // Named once the stages are done: a backend still being set up (the CLI's) is waited for
  // only when a stage first needs it.
  r.backend = backend.name();
  r.device = backend.device();
  return r;
}

}  // namespace groovetrace
