// The files of a synthetic scan: SCAN.pcd, SCAN.truth.json and SCAN.labels.pcd
// (format in docs/synthetic-scans.md), written and read back.

#include <cmath>
#include <fstream>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "io/pcd.hpp"
#include "synth/internal.hpp"

namespace groovetrace {
namespace {

using nlohmann::json;

constexpr const char* kTruthFormat = "groovetrace-synth-truth";
constexpr int kTruthVersion = 1;

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string dir_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

Eigen::Vector3d to_vec(const json& j) {
  if (!j.is_array() || j.size() != 3) throw InputError("truth: expected a 3-vector");
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

json params_json(const SynthParams& p) {
  const SensorModel& m = p.sensor;
  return json{
      {"shape", shape_name(p.shape)},
      {"groove_width_m", p.groove_width},
      {"groove_angle_deg", p.groove_angle_deg},
      {"groove_depth_m", p.groove_depth},
      {"root_gap_m", p.root_gap},
      {"distance_m", p.distance},
      {"tilt_deg", p.tilt_deg},
      {"roll_deg", p.roll_deg},
      {"width", p.width},
      {"height", p.height},
      {"seed", p.seed},
      {"noise", p.noise},
      {"effects", effects_string(p.effects)},
      {"depth_unit_m", p.depth_unit},
      {"joint", joint_name(p.joint)},
      {"misalignment_m", p.misalignment},
      {"tacks", p.tacks},
      {"tack_height_fraction", p.tack_height_fraction},
      {"clamps", p.clamps},
      {"clutter", p.clutter},
      {"pipe_diameter_m", p.pipe_diameter},
      {"sensor",
       {{"hfov_deg", m.hfov_deg},
        {"vfov_deg", m.vfov_deg},
        {"baseline_m", m.baseline},
        {"subpixel_px", m.subpixel},
        {"correlate_noise", m.correlate_noise},
        {"undulation_disparity_px", m.undulation_disparity},
        {"undulation_min_wavelength_m", m.undulation_min_wavelength},
        {"undulation_max_wavelength_m", m.undulation_max_wavelength},
        {"blur_radius_1280_px", m.blur_radius_1280},
        {"jump_disparity_px", m.jump_disparity},
        {"flying_probability", m.flying_probability},
        {"grazing_start_deg", m.grazing_start_deg},
        {"grazing_full_deg", m.grazing_full_deg},
        {"dropout_probability", m.dropout_probability},
        {"min_z_m", m.min_z}}},
  };
}

SynthParams params_from_json(const json& j) {
  SynthParams p;
  p.shape = parse_shape(j.at("shape").get<std::string>());
  p.groove_width = j.at("groove_width_m").get<double>();
  p.groove_angle_deg = j.at("groove_angle_deg").get<double>();
  p.groove_depth = j.at("groove_depth_m").get<double>();
  p.root_gap = j.at("root_gap_m").get<double>();
  p.distance = j.at("distance_m").get<double>();
  p.tilt_deg = j.at("tilt_deg").get<double>();
  p.roll_deg = j.at("roll_deg").get<double>();
  p.width = j.at("width").get<int>();
  p.height = j.at("height").get<int>();
  p.seed = j.at("seed").get<std::uint64_t>();
  p.noise = j.at("noise").get<bool>();
  p.effects = parse_effects(j.at("effects").get<std::string>());
  p.depth_unit = j.at("depth_unit_m").get<double>();
  // Issue 12's parameters; older truth files have none of them (the defaults).
  const SynthParams defaults;
  p.joint = parse_joint(j.value("joint", std::string(joint_name(defaults.joint))));
  p.misalignment = j.value("misalignment_m", defaults.misalignment);
  p.tacks = j.value("tacks", defaults.tacks);
  p.tack_height_fraction = j.value("tack_height_fraction", defaults.tack_height_fraction);
  p.clamps = j.value("clamps", defaults.clamps);
  p.clutter = j.value("clutter", defaults.clutter);
  p.pipe_diameter = j.value("pipe_diameter_m", defaults.pipe_diameter);
  const json& s = j.at("sensor");
  SensorModel& m = p.sensor;
  m.hfov_deg = s.at("hfov_deg").get<double>();
  m.vfov_deg = s.at("vfov_deg").get<double>();
  m.baseline = s.at("baseline_m").get<double>();
  m.subpixel = s.at("subpixel_px").get<double>();
  m.correlate_noise = s.at("correlate_noise").get<bool>();
  m.undulation_disparity = s.at("undulation_disparity_px").get<double>();
  m.undulation_min_wavelength = s.at("undulation_min_wavelength_m").get<double>();
  m.undulation_max_wavelength = s.at("undulation_max_wavelength_m").get<double>();
  m.blur_radius_1280 = s.at("blur_radius_1280_px").get<int>();
  m.jump_disparity = s.at("jump_disparity_px").get<double>();
  m.flying_probability = s.at("flying_probability").get<double>();
  m.grazing_start_deg = s.at("grazing_start_deg").get<double>();
  m.grazing_full_deg = s.at("grazing_full_deg").get<double>();
  m.dropout_probability = s.at("dropout_probability").get<double>();
  m.min_z = s.at("min_z_m").get<double>();
  return p;
}

std::string read_file(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(std::string("cannot read ") + what + " " + path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

Seam seam_from_json(const json& s, const std::string& path) {
  Seam seam;
  seam.closed = s.at("closed").get<bool>();
  for (const json& v : s.at("root")) seam.root.push_back(to_vec(v));
  for (const json& v : s.at("normal")) seam.normal.push_back(to_vec(v));
  for (const json& v : s.at("bisector")) seam.bisector.push_back(to_vec(v));
  seam.in_view = s.at("in_view").get<std::vector<std::uint8_t>>();
  // Older truth files: a V without tacks.
  seam.joint = parse_joint(s.value("joint", std::string("V")));
  if (s.contains("tacks")) {
    for (const json& t : s.at("tacks"))
      seam.tacks.push_back({t.at("position_m").get<double>(), to_vec(t.at("centre")),
                            t.at("length_m").get<double>(), t.at("height_m").get<double>()});
  }
  if (seam.normal.size() != seam.root.size() || seam.bisector.size() != seam.root.size() ||
      seam.in_view.size() != seam.root.size())
    throw InputError("truth: " + path + ": seam arrays differ in length");
  return seam;
}

// Everything of the truth but the labels. Throws json::exception for a missing or mistyped
// key, UsageError for an unknown shape or effect.
void truth_from_json(const json& j, const std::string& path, SynthTruth& truth) {
  if (j.at("format").get<std::string>() != kTruthFormat)
    throw InputError("truth: " + path + " is not a groovetrace truth file");
  truth.params = params_from_json(j.at("params"));
  const json& g = j.at("groove");
  truth.groove.top_width = g.at("top_width_m").get<double>();
  truth.groove.depth = g.at("depth_m").get<double>();
  truth.groove.included_angle_deg = g.at("included_angle_deg").get<double>();
  truth.groove.root_gap = g.at("root_gap_m").get<double>();
  truth.groove.thickness = g.at("thickness_m").get<double>();
  truth.groove.misalignment = g.value("misalignment_m", 0.0);
  const json& c = j.at("camera");
  truth.camera.width = c.at("width").get<int>();
  truth.camera.height = c.at("height").get<int>();
  truth.camera.fx = c.at("fx").get<double>();
  truth.camera.fy = c.at("fy").get<double>();
  truth.camera.cx = c.at("cx").get<double>();
  truth.camera.cy = c.at("cy").get<double>();
  const json& pose = j.at("T_workpiece_camera");
  Eigen::Matrix4d T;
  for (int r = 0; r < 4; ++r)
    for (int k = 0; k < 4; ++k) T(r, k) = pose.at(r).at(k).get<double>();
  truth.T_workpiece_camera.matrix() = T;
  for (const json& s : j.at("seams")) truth.seams.push_back(seam_from_json(s, path));
}

// SCAN.labels.pcd: `label` and `valid` per point of the camera's image.
void read_labels(const std::string& path, SynthTruth& truth) {
  io::PcdTable table;
  try {
    table = io::read_pcd_fields(path, {"label", "valid"});
  } catch (const InputError& e) {
    throw InputError(std::string("truth: ") + e.what());
  }
  if (table.width != static_cast<std::uint32_t>(truth.camera.width) ||
      table.height != static_cast<std::uint32_t>(truth.camera.height))
    throw InputError("truth: " + path + " is not a labels file for a " +
                     std::to_string(truth.camera.width) + "x" +
                     std::to_string(truth.camera.height) + " scan");
  const std::vector<float>& label = *table.column("label");
  const std::vector<float>& valid = *table.column("valid");
  truth.label.resize(label.size());
  truth.valid.resize(valid.size());
  for (std::size_t i = 0; i < label.size(); ++i) {
    truth.label[i] = label[i] != 0.0f ? 1 : 0;
    truth.valid[i] = valid[i] != 0.0f ? 1 : 0;
  }
}

json seam_json(const Seam& s, const GrooveGeometry& g) {
  json root = json::array(), normal = json::array(), bisector = json::array();
  for (std::size_t k = 0; k < s.root.size(); ++k) {
    root.push_back(vec(s.root[k]));
    normal.push_back(vec(s.normal[k]));
    bisector.push_back(vec(s.bisector[k]));
  }
  json tacks = json::array();
  for (const Tack& t : s.tacks)
    tacks.push_back({{"position_m", t.position},
                     {"centre", vec(t.centre)},
                     {"length_m", t.length},
                     {"height_m", t.height}});
  return {{"closed", s.closed},
          {"joint", joint_name(s.joint)},
          {"geometry",
           {{"top_width_m", g.top_width},
            {"depth_m", g.depth},
            {"included_angle_deg", g.included_angle_deg},
            {"root_gap_m", g.root_gap},
            {"misalignment_m", g.misalignment}}},
          {"tacks", tacks},
          {"length_m", s.length()},
          {"length_in_view_m", s.length_in_view()},
          {"root", root},
          {"normal", normal},
          {"bisector", bisector},
          {"in_view", s.in_view}};
}

}  // namespace

SynthFiles synth_files(const std::string& scan_path) {
  const std::string ext = ".pcd";
  if (scan_path.size() <= ext.size() ||
      scan_path.compare(scan_path.size() - ext.size(), ext.size(), ext) != 0 ||
      base_name(scan_path) == ext)
    throw UsageError("synth: the scan's file name must end in .pcd, got '" + scan_path + "'");
  const std::string stem = scan_path.substr(0, scan_path.size() - ext.size());
  return {scan_path, stem + ".truth.json", stem + ".labels.pcd"};
}

std::string truth_json(const SynthTruth& truth, const std::string& scan_name,
                       const std::string& labels_name) {
  std::size_t valid = 0, labelled = 0, labelled_valid = 0;
  for (std::size_t i = 0; i < truth.label.size(); ++i) {
    valid += truth.valid[i];
    labelled += truth.label[i] ? 1 : 0;
    labelled_valid += truth.label[i] && truth.valid[i] ? 1 : 0;
  }
  json seams = json::array();
  for (const Seam& s : truth.seams) seams.push_back(seam_json(s, truth.groove));
  const Eigen::Matrix4d T = truth.T_workpiece_camera.matrix();
  json pose = json::array();
  for (int r = 0; r < 4; ++r) pose.push_back({T(r, 0), T(r, 1), T(r, 2), T(r, 3)});
  const CameraModel& c = truth.camera;
  const GrooveGeometry& g = truth.groove;
  const json j = {
      {"format", kTruthFormat},
      {"version", kTruthVersion},
      {"units", "m"},
      {"frame", "camera: x right, y down, z forward; origin at the left imager"},
      {"files", {{"scan", scan_name}, {"labels", labels_name}}},
      {"params", params_json(truth.params)},
      {"groove",
       {{"top_width_m", g.top_width},
        {"depth_m", g.depth},
        {"included_angle_deg", g.included_angle_deg},
        {"root_gap_m", g.root_gap},
        {"thickness_m", g.thickness},
        {"misalignment_m", g.misalignment}}},
      {"camera",
       {{"width", c.width},
        {"height", c.height},
        {"fx", c.fx},
        {"fy", c.fy},
        {"cx", c.cx},
        {"cy", c.cy},
        {"baseline_m", truth.params.sensor.baseline}}},
      {"T_workpiece_camera", pose},
      {"counts",
       {{"points", truth.label.size()},
        {"valid", valid},
        {"groove_labelled", labelled},
        {"groove_valid", labelled_valid}}},
      {"seams", seams},
  };
  return j.dump() + "\n";
}

std::string labels_pcd_bytes(const SynthTruth& truth) {
  return io::binary_pcd_bytes(
      "groovetrace synth labels: label (1 = groove wall), valid (1 = return)",
      static_cast<std::size_t>(truth.camera.width), static_cast<std::size_t>(truth.camera.height),
      Eigen::Vector3f::Zero(),
      {io::flag_column("label", &truth.label), io::flag_column("valid", &truth.valid)});
}

SynthFiles write_synth_scan(const SynthScan& scan, const std::string& scan_path) {
  const SynthFiles files = synth_files(scan_path);
  // Truth first: a scan that exists always has its truth beside it.
  write_file_atomic(files.labels, labels_pcd_bytes(scan.truth));
  write_file_atomic(files.truth,
                    truth_json(scan.truth, base_name(files.scan), base_name(files.labels)));
  write_file_atomic(files.scan, pcd_bytes(scan.cloud));
  return files;
}

SynthTruth read_synth_truth(const std::string& scan_path) {
  SynthFiles files;
  try {
    files = synth_files(scan_path);
  } catch (const UsageError&) {
    throw InputError("truth: '" + scan_path + "' is not a .pcd scan path");
  }
  json j;
  try {
    j = json::parse(read_file(files.truth, "truth file"));
  } catch (const json::exception& e) {
    throw InputError("truth: " + files.truth + " is not valid JSON: " + e.what());
  }
  SynthTruth truth;
  try {
    truth_from_json(j, files.truth, truth);
  } catch (const json::exception& e) {
    throw InputError("truth: " + files.truth + ": " + e.what());
  } catch (const UsageError& e) {
    throw InputError("truth: " + files.truth + ": " + e.what());
  }
  std::string labels_path = files.labels;
  if (j.contains("files") && j["files"].contains("labels"))
    labels_path = dir_name(files.truth) + j["files"]["labels"].get<std::string>();
  read_labels(labels_path, truth);
  return truth;
}

}  // namespace groovetrace
