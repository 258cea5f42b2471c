#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <groovetrace/cloud.hpp>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "io/text.hpp"

namespace groovetrace {
namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

double parse_number(const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  std::size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(t, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (t.empty() || used != t.size() || !std::isfinite(v)) {
    throw UsageError(key + ": expected a number, got '" + text + "'");
  }
  return v;
}

double in_range(const std::string& key, const std::string& text, double lo, double hi,
                const std::string& unit) {
  const double v = parse_number(key, text);
  if (v < lo || v > hi) {
    std::ostringstream m;
    m << key << ": " << text << " is out of range [" << lo << ", " << hi << "]" << unit;
    throw UsageError(m.str());
  }
  return v;
}

int int_in_range(const std::string& key, const std::string& text, int lo, int hi) {
  const double v = in_range(key, text, lo, hi, "");
  if (v != std::floor(v)) throw UsageError(key + ": expected an integer, got '" + text + "'");
  return static_cast<int>(v);
}

bool parse_bool(const std::string& key, const std::string& text) {
  const std::string t = trim(text);
  if (t == "true" || t == "1" || t == "on" || t == "yes") return true;
  if (t == "false" || t == "0" || t == "off" || t == "no") return false;
  throw UsageError(key + ": expected true or false, got '" + text + "'");
}

std::string one_of(const std::string& key, const std::string& text,
                   const std::vector<std::string>& allowed) {
  const std::string t = trim(text);
  std::string list;
  for (const auto& a : allowed) {
    if (t == a) return t;
    list += (list.empty() ? "" : ", ") + a;
  }
  throw UsageError(key + ": expected one of " + list + ", got '" + text + "'");
}

// A non-finite number is null, as in report.json's other numbers: "inf" is not JSON. validate
// refuses a null where a number belongs.
std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}
// A path or device name need not be UTF-8 (Linux file names are bytes); report.json shows its
// invalid bytes as U+FFFD rather than failing (nlohmann's type_error was exit 5).
std::string quoted(const std::string& s) {
  return nlohmann::json(s).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// A field of one group of Params (the common ones are the group Params itself).
template <class Group, class T>
struct Field {
  Group Params::*group;
  T Group::*member;
  T& of(Params& p) const { return p.*group.*member; }
  const T& of(const Params& p) const { return p.*group.*member; }
};
template <class T>
Field<PaperParams, T> paper(T PaperParams::*member) {
  return {&Params::paper, member};
}
template <class T>
Field<RobustParams, T> robust(T RobustParams::*member) {
  return {&Params::robust, member};
}
template <class T>
Field<ProgramParams, T> program(T ProgramParams::*member) {
  return {&Params::program, member};
}

template <class T>
Field<WeldParams, T> weld(T WeldParams::*member) {
  return {&Params::weld, member};
}
template <class T>
Field<GuardParams, T> guard(T GuardParams::*member) {
  return {&Params::guards, member};
}

// A length parameter in metres with a plausible range, so that "--radius 3" (meant as mm)
// is refused instead of running for an hour.
template <class F>
ParamSpec length(ParamScope scope, const std::string& key, const std::string& help, F field,
                 double lo, double hi) {
  return {key, help + " (m)", scope,
          [=](Params& p, const std::string& t) { field.of(p) = in_range(key, t, lo, hi, " m"); },
          [=](const Params& p) { return num(field.of(p)); }};
}
template <class F>
ParamSpec real(ParamScope scope, const std::string& key, const std::string& help, F field,
               double lo, double hi, const std::string& unit) {
  return {
      key, help + " (" + unit + ")", scope,
      [=](Params& p, const std::string& t) { field.of(p) = in_range(key, t, lo, hi, " " + unit); },
      [=](const Params& p) { return num(field.of(p)); }};
}
template <class F>
ParamSpec integer(ParamScope scope, const std::string& key, const std::string& help, F field,
                  int lo, int hi) {
  return {key, help, scope,
          [=](Params& p, const std::string& t) { field.of(p) = int_in_range(key, t, lo, hi); },
          [=](const Params& p) { return std::to_string(field.of(p)); }};
}
template <class F>
ParamSpec boolean(const std::string& key, const std::string& help, F field) {
  return {key,
          help,
          ParamScope::common,
          [=](Params& p, const std::string& t) { field.of(p) = parse_bool(key, t); },
          [=](const Params& p) { return std::string(field.of(p) ? "true" : "false"); },
          nullptr,
          false,
          true};
}
ParamSpec choice(const std::string& key, const std::string& help, std::string Params::*field,
                 std::vector<std::string> allowed) {
  return {key, help, ParamScope::common,
          [=](Params& p, const std::string& t) { p.*field = one_of(key, t, allowed); },
          [=](const Params& p) { return quoted(p.*field); }};
}
// A file path; report.json shows it absolute, so that the report, as a config file, finds it.
ParamSpec path(const std::string& key, const std::string& help, std::string Params::*field) {
  return {key,
          help,
          ParamScope::common,
          [=](Params& p, const std::string& t) {
            if (trim(t).empty()) throw UsageError(key + ": expected a file path");
            p.*field = t;
          },
          [=](const Params& p) {
            if ((p.*field).empty()) return std::string("null");
            std::error_code ec;
            const auto absolute = std::filesystem::absolute(p.*field, ec).lexically_normal();
            return quoted(ec ? p.*field : absolute.string());
          },
          [=](Params& p) { (p.*field).clear(); },
          true};
}

// The viewpoint is in metres whatever --units says, and bounded as a scan's points are: a
// coordinate beyond kMaxCoordinate is a wrong unit or a typo. Unbounded, a finite double such
// as 1.1e97 became inf in the float it is kept in, which validate refused and params_json
// printed as "inf" (fuzz_config_yaml).
Eigen::Vector3f parse_viewpoint(const std::string& t) {
  std::stringstream ss(t);
  std::string part;
  std::vector<double> v;
  while (std::getline(ss, part, ',')) {
    v.push_back(in_range("viewpoint", part, -kMaxCoordinate, kMaxCoordinate, " m"));
  }
  if (v.size() != 3) {
    throw UsageError("viewpoint: expected X,Y,Z (three numbers), got '" + t + "'");
  }
  return Eigen::Vector3f(v[0], v[1], v[2]);
}

std::string viewpoint_json(const Params& p) {
  if (!p.viewpoint) return "null";
  return "[" + num(p.viewpoint->x()) + "," + num(p.viewpoint->y()) + "," + num(p.viewpoint->z()) +
         "]";
}

// The common parameters: method, backend, input units and viewpoint.
void add_common_specs(std::vector<ParamSpec>& s) {
  constexpr auto kCommon = ParamScope::common;
  s.push_back({"method", "detection method: robust (docs/method-robust.md) or paper (as published)",
               kCommon,
               [](Params& p, const std::string& t) {
                 p.method = one_of("method", t, {"paper", "robust"}) == "paper" ? Method::paper
                                                                                : Method::robust;
               },
               [](const Params& p) { return quoted(to_string(p.method)); }});
  s.push_back(choice("backend", "feature backend: auto, cpu or opencl", &Params::backend,
                     {"auto", "cpu", "opencl"}));
  s.push_back({"device",
               "OpenCL device: its index N or part of its name; none: first GPU, "
               "else first device",
               kCommon, [](Params& p, const std::string& t) { p.device = trim(t); },
               [](const Params& p) { return quoted(p.device); }});
  s.push_back({"units", "unit of the input coordinates: m or mm", kCommon,
               [](Params& p, const std::string& t) {
                 p.units_scale = one_of("units", t, {"m", "mm"}) == "mm" ? 0.001 : 1.0;
               },
               [](const Params& p) { return quoted(p.units_scale == 1.0 ? "m" : "mm"); }});
}

// The paper method's features and detection.
void add_paper_specs(std::vector<ParamSpec>& s) {
  constexpr auto kPaper = ParamScope::paper;
  s.push_back({"smooth", "MLS smoothing before normals: true or false", kPaper,
               [](Params& p, const std::string& t) { p.paper.smooth = parse_bool("smooth", t); },
               [](const Params& p) { return std::string(p.paper.smooth ? "true" : "false"); }});
  s.push_back(length(kPaper, "mls_radius", "MLS search radius", paper(&PaperParams::mls_radius),
                     1e-5, 0.1));
  s.push_back(integer(kPaper, "mls_order", "MLS polynomial order: 1 plane, 2 quadric",
                      paper(&PaperParams::mls_order), 1, 2));
  s.push_back(length(kPaper, "radius", "neighbourhood radius r for normals and the GFH",
                     paper(&PaperParams::radius), 1e-5, 0.1));
  s.push_back(integer(kPaper, "min_neighbors", "fewer neighbours within r: no normal, never groove",
                      paper(&PaperParams::min_neighbors), 3, 100000));
}

void add_detection_specs(std::vector<ParamSpec>& s) {
  constexpr auto kPaper = ParamScope::paper;
  s.push_back({"threshold", "descriptor threshold T (deg^2; paper 4.5-5) or auto (Otsu on log D)",
               kPaper,
               [](Params& p, const std::string& t) {
                 p.paper.threshold_auto = trim(t) == "auto";
                 if (!p.paper.threshold_auto) {
                   p.paper.threshold = in_range("threshold", t, 0.0, 1e6, " deg^2");
                 }
               },
               [](const Params& p) {
                 return p.paper.threshold_auto ? quoted("auto") : num(p.paper.threshold);
               }});
  s.push_back(integer(kPaper, "min_component", "groove parts with fewer points are dropped",
                      paper(&PaperParams::min_component), 1, 100000000));
  s.push_back(length(kPaper, "link_distance", "max gap within one groove part; 0 = radius",
                     paper(&PaperParams::link_distance), 0.0, 0.1));
}

// Waypoints: `slices` is both methods' (paper: always, default 50; robust: only when given,
// else `step`), so it sets both; report.json shows the chosen method's own value (null: the
// robust method's `step`), which set back gives the same run.
void add_waypoint_specs(std::vector<ParamSpec>& s) {
  constexpr auto kRobust = ParamScope::robust;
  constexpr auto kPaper = ParamScope::paper;
  s.push_back({"slices",
               "slices along the groove, one waypoint each (paper: 50 if not given; robust: "
               "given, it wins over step)",
               ParamScope::common,
               [](Params& p, const std::string& t) {
                 p.paper.slices = p.robust.slices = int_in_range("slices", t, 2, 100000);
               },
               [](const Params& p) {
                 if (p.method == Method::paper) return std::to_string(p.paper.slices);
                 return p.robust.slices == 0 ? std::string("null")
                                             : std::to_string(p.robust.slices);
               },
               [](Params& p) {
                 p.paper.slices = PaperParams().slices;
                 p.robust.slices = RobustParams().slices;
               }});
  s.push_back(length(kRobust, "step", "robust: waypoint spacing along the seam",
                     robust(&RobustParams::step), 1e-4, 0.1));
  s.push_back(
      integer(kRobust, "max_seams",
              "robust: seams exported, best first (trajectory.csv, then trajectory_1.csv...)",
              robust(&RobustParams::max_seams), 1, 100));
  s.push_back(length(kRobust, "orientation_blend",
                     "robust: arc length over which the torch's orientation turns through "
                     "corners; 0 = no blending",
                     robust(&RobustParams::orientation_blend), 0.0, 0.5));
  s.push_back(length(kRobust, "fillet_leg",
                     "robust: leg of the fillet weld on a corner joint (fillet, lap); it bounds "
                     "the joint region",
                     robust(&RobustParams::fillet_leg), 0.001, 0.05));
  s.push_back(integer(kPaper, "median_max_iterations", "geometric-median iteration cap",
                      paper(&PaperParams::median_max_iterations), 1, 1000000));
  s.push_back(length(kPaper, "median_tolerance", "geometric-median stop step",
                     paper(&PaperParams::median_tolerance), 1e-12, 1e-3));
}

Robot parse_robot(const std::string& text) {
  const std::string t = one_of("robot", text, {"ur", "abb", "kuka"});
  return t == "abb" ? Robot::abb : t == "kuka" ? Robot::kuka : Robot::ur;
}

// The robot program (program.hpp, docs/robot.md).
void add_program_specs(std::vector<ParamSpec>& s) {
  constexpr auto kCommon = ParamScope::common;
  s.push_back({"robot",
               "robot program: ur (program.script), abb (program.mod) or kuka (program.src and "
               "program.dat)",
               kCommon, [](Params& p, const std::string& t) { p.program.robot = parse_robot(t); },
               [](const Params& p) { return quoted(to_string(p.program.robot)); }});
  s.push_back(boolean("dry_run", "the same program with the arc never switched on",
                      program(&ProgramParams::dry_run)));
  s.push_back(length(kCommon, "approach_offset", "approach and retreat distance along -tool z",
                     program(&ProgramParams::approach_offset), 0.0, 1.0));
  s.push_back(real(kCommon, "approach_speed", "approach and retreat speed",
                   program(&ProgramParams::approach_speed), 1e-4, 3.0, "m/s"));
  s.push_back(real(kCommon, "weld_speed", "travel speed along the seam",
                   program(&ProgramParams::weld_speed), 1e-5, 1.0, "m/s"));
  s.push_back(real(kCommon, "acceleration", "tool acceleration",
                   program(&ProgramParams::acceleration), 1e-3, 10.0, "m/s^2"));
  s.push_back(length(kCommon, "blend_radius",
                     "movep blend radius, capped at 0.4 of the shorter segment",
                     program(&ProgramParams::blend_radius), 0.0, 0.1));
  s.push_back(integer(kCommon, "arc_output",
                      "output that switches the arc: ur standard digital output 0..7, kuka "
                      "$OUT[1..4096], abb signal doArcN",
                      program(&ProgramParams::arc_output), 0, 4096));
  s.push_back(real(kCommon, "arc_delay", "wait after arc on", program(&ProgramParams::arc_delay),
                   0.0, 60.0, "s"));
}

// The box as xmin,ymin,zmin,xmax,ymax,zmax (m, base frame); "null" or "" for none.
std::optional<Eigen::AlignedBox3d> parse_workspace(const std::string& t) {
  if (trim(t).empty() || trim(t) == "null") return std::nullopt;
  std::stringstream ss(t);
  std::string part;
  std::vector<double> v;
  while (std::getline(ss, part, ',')) v.push_back(parse_number("workspace", part));
  if (v.size() != 6) {
    throw UsageError("workspace: expected XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX (six numbers, m), got '" +
                     t + "'");
  }
  const Eigen::Vector3d lo(v[0], v[1], v[2]), hi(v[3], v[4], v[5]);
  if (!(lo.array() < hi.array()).all()) {
    throw UsageError("workspace: each minimum must be below its maximum, got '" + t + "'");
  }
  return Eigen::AlignedBox3d(lo, hi);
}

std::string workspace_json(const Params& p) {
  if (!p.guards.workspace) return "null";
  const Eigen::Vector3d lo = p.guards.workspace->min(), hi = p.guards.workspace->max();
  return "[" + num(lo.x()) + "," + num(lo.y()) + "," + num(lo.z()) + "," + num(hi.x()) + "," +
         num(hi.y()) + "," + num(hi.z()) + "]";
}

// Torch angles, weaving and passes (docs/robot.md).
void add_weld_specs(std::vector<ParamSpec>& s) {
  constexpr auto kCommon = ParamScope::common;
  s.push_back(real(kCommon, "travel_angle", "torch travel angle about tool y: + push, - drag",
                   weld(&WeldParams::travel_angle), -60.0, 60.0, "deg"));
  s.push_back(real(kCommon, "work_angle", "torch work angle about the seam (tool x)",
                   weld(&WeldParams::work_angle), -60.0, 60.0, "deg"));
  s.push_back({"weave", "weave pattern across the groove: none, zigzag, sine or triangle", kCommon,
               [](Params& p, const std::string& t) {
                 p.weld.weave = one_of("weave", t, {"none", "zigzag", "sine", "triangle"});
               },
               [](const Params& p) { return quoted(p.weld.weave); }});
  s.push_back(length(kCommon, "weave_amplitude",
                     "weave: from the root line to either side, at most half the fitted opening",
                     weld(&WeldParams::weave_amplitude), 0.0, 0.05));
  s.push_back(length(kCommon, "weave_wavelength", "weave: length of one period along the seam",
                     weld(&WeldParams::weave_wavelength), 5e-4, 0.1));
  s.push_back(boolean("multi_pass", "robust: root, fill and cap passes planned from the fitted V",
                      weld(&WeldParams::multi_pass)));
  s.push_back(real(kCommon, "bead_area", "weld metal per pass; 0 = wire area * feed / weld speed",
                   weld(&WeldParams::bead_area), 0.0, 1e-3, "m^2"));
  s.push_back(length(kCommon, "wire_diameter", "welding wire diameter",
                     weld(&WeldParams::wire_diameter), 2e-4, 0.005));
  s.push_back(real(kCommon, "wire_feed", "wire feed speed", weld(&WeldParams::wire_feed), 1e-3, 1.0,
                   "m/s"));
}

// The checks every program passes before it is written (docs/robot.md, "Guards").
void add_guard_specs(std::vector<ParamSpec>& s) {
  constexpr auto kCommon = ParamScope::common;
  s.push_back(length(kCommon, "max_step", "guard: largest step between consecutive poses",
                     guard(&GuardParams::max_step), 1e-4, 1.0));
  s.push_back(real(kCommon, "max_step_rotation", "guard: largest turn between consecutive poses",
                   guard(&GuardParams::max_step_rotation), 0.1, 180.0, "deg"));
  s.push_back({"workspace",
               "guard: every pose inside XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX of the base frame (m); "
               "needs --hand-eye and --flange-pose",
               kCommon,
               [](Params& p, const std::string& t) { p.guards.workspace = parse_workspace(t); },
               workspace_json, [](Params& p) { p.guards.workspace.reset(); }});
  s.push_back(boolean("camera_frame_program",
                      "write the robot program even when its poses are in the camera frame",
                      guard(&GuardParams::camera_frame_program)));
}

std::vector<ParamSpec> build_specs() {
  std::vector<ParamSpec> s;
  add_common_specs(s);
  add_paper_specs(s);
  s.push_back({"viewpoint",
               "sensor origin X,Y,Z in the cloud's frame (m); none: PCD "
               "VIEWPOINT, else the origin",
               ParamScope::common,
               [](Params& p, const std::string& t) { p.viewpoint = parse_viewpoint(t); },
               viewpoint_json, [](Params& p) { p.viewpoint.reset(); }});
  add_detection_specs(s);
  add_waypoint_specs(s);
  add_program_specs(s);
  add_weld_specs(s);
  add_guard_specs(s);
  s.push_back(path("hand_eye", "T_flange_camera file (any layout of docs/frames.md)",
                   &Params::hand_eye_file));
  s.push_back(path("flange_pose", "T_base_flange at capture (any layout of docs/frames.md)",
                   &Params::flange_pose_file));
  s.push_back(path("intrinsics",
                   "depth PNG scans: intrinsics JSON (fx, fy, ppx, ppy px; depth_scale m/unit); "
                   "default: STEM.json, else intrinsics.json beside the PNG",
                   &Params::intrinsics_file));
  return s;
}

std::string underscored(std::string key) {
  for (char& c : key) {
    if (c == '-') c = '_';
  }
  return key;
}

}  // namespace

const char* to_string(Method method) { return method == Method::paper ? "paper" : "robust"; }

const char* to_string(Robot robot) {
  return robot == Robot::abb ? "abb" : robot == Robot::kuka ? "kuka" : "ur";
}

const std::vector<ParamSpec>& param_specs() {
  static const std::vector<ParamSpec> specs = build_specs();
  return specs;
}

void set_param(Params& params, const std::string& key, const std::string& value) {
  const std::string k = underscored(key);
  for (const auto& spec : param_specs()) {
    if (spec.key != k) continue;
    try {
      spec.set(params, value);
    } catch (const UsageError& e) {
      // The message quotes the value, which a config file may split over lines.
      throw UsageError(io::shown(e.what()));
    }
    return;
  }
  throw UsageError("unknown parameter '" + io::shown(key, 100) + "'");
}

namespace {

namespace fs = std::filesystem;

// One key: value of a config file; nullopt for a null.
using Entry = std::pair<std::string, std::optional<std::string>>;

// A YAML key for a message: its text, or "a key" when it is no scalar.
std::string shown_key(const YAML::Node& key) {
  return key.IsScalar() ? io::shown(key.Scalar(), 100) : std::string("a key");
}

// A report.json (or its YAML twin) holds the run's parameters under `parameters`; a failed
// run's report has none.
template <class Contains>
void require_parameters(const std::string& path, bool has_parameters, Contains contains) {
  if (!has_parameters && contains("status") && contains("exit_code")) {
    throw InputError("config file " + path +
                     " is a groovetrace report without parameters (a failed run's)");
  }
}

std::vector<Entry> json_entries(const std::string& path, const std::string& text) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    throw InputError("config file " + path + " is not valid JSON");
  }
  if (!j.is_object()) throw InputError("config file " + path + " must hold a JSON object");
  const bool report = j.contains("parameters") && j["parameters"].is_object();
  require_parameters(path, report, [&](const char* k) { return j.contains(k); });
  std::vector<Entry> entries;
  for (const auto& [k, v] : (report ? j["parameters"] : j).items()) {
    if (v.is_null()) {
      entries.emplace_back(k, std::nullopt);
    } else if (v.is_string()) {
      entries.emplace_back(k, v.get<std::string>());
    } else if (v.is_array()) {
      std::string joined;
      for (const auto& e : v) joined += (joined.empty() ? "" : ",") + e.dump();
      entries.emplace_back(k, joined);
    } else {
      entries.emplace_back(k, v.dump());
    }
  }
  return entries;
}

std::vector<Entry> yaml_entries(const std::string& path, const std::string& text) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const std::exception& e) {
    throw InputError("config file " + path + " is not valid YAML");
  }
  if (root.IsNull()) return {};
  if (!root.IsMap()) throw InputError("config file " + path + " must hold a YAML map");
  const bool report = root["parameters"] && root["parameters"].IsMap();
  require_parameters(path, report, [&](const char* k) { return bool(root[k]); });
  std::vector<Entry> entries;
  for (const auto& kv : report ? root["parameters"] : root) {
    // A key or list element that is itself a list or map is no value (yaml-cpp's "bad
    // conversion" was exit 5). Only a list is searched for them: a map's entries are no
    // nodes, and asking one IsScalar() threw YAML::InvalidNode (exit 5 too).
    const bool scalars =
        kv.second.IsSequence() && std::all_of(kv.second.begin(), kv.second.end(),
                                              [](const YAML::Node& e) { return e.IsScalar(); });
    const bool null = kv.second.IsNull();
    if (!kv.first.IsScalar() || !(kv.second.IsScalar() || scalars || null)) {
      throw UsageError("config file " + path + ": " + shown_key(kv.first) +
                       " must be a value or a list of values");
    }
    const std::string k = kv.first.as<std::string>();
    if (null) {
      entries.emplace_back(k, std::nullopt);
    } else if (kv.second.IsSequence()) {
      std::string joined;
      for (const auto& e : kv.second) joined += (joined.empty() ? "" : ",") + e.as<std::string>();
      entries.emplace_back(k, joined);
    } else {
      entries.emplace_back(k, kv.second.as<std::string>());
    }
  }
  return entries;
}

const ParamSpec* find_spec(const std::string& key) {
  for (const auto& spec : param_specs()) {
    if (spec.key == key) return &spec;
  }
  return nullptr;
}

// One entry: a null unsets an optional parameter; a relative file path is the config
// folder's.
void apply_entry(Params& params, const Entry& entry, const fs::path& folder) {
  const auto& [key, value] = entry;
  const ParamSpec* spec = find_spec(underscored(key));
  if (!value) {
    if (!spec) throw UsageError("unknown parameter '" + io::shown(key, 100) + "'");
    if (!spec->unset) {
      throw UsageError(spec->key + ": null is no value here (only an optional parameter " +
                       "takes null: viewpoint, slices, a file)");
    }
    spec->unset(params);
    return;
  }
  std::string text = *value;
  if (spec && spec->file_path && !trim(text).empty() && fs::path(text).is_relative()) {
    text = (folder / text).lexically_normal().string();
  }
  set_param(params, key, text);
}

}  // namespace

std::vector<std::string> apply_config_file(Params& params, const std::string& path) {
  const std::string text = io::read_all(path, true);
  io::require_shallow(text, path);
  const std::string ext = io::lower_extension(path);
  std::vector<Entry> entries;
  if (ext == ".json") {
    entries = json_entries(path, text);
  } else if (ext == ".yaml" || ext == ".yml") {
    entries = yaml_entries(path, text);
  } else {
    throw InputError("config file " + path + " must end in .yaml, .yml or .json");
  }
  const fs::path folder = fs::path(path).parent_path();
  for (const auto& entry : entries) {
    try {
      apply_entry(params, entry, folder);
    } catch (const UsageError& e) {
      throw UsageError("config file " + path + ": " + e.what());
    }
  }
  // The keys whose value differs from the default: report.json, as a config, lists every
  // key, the other method's at their defaults, and those need no warning.
  const Params defaults;
  std::vector<std::string> keys;
  for (const auto& entry : entries) {
    const ParamSpec* spec = find_spec(underscored(entry.first));
    if (spec && spec->json(params) != spec->json(defaults)) keys.push_back(spec->key);
  }
  return keys;
}

std::string other_method_warning(const Params& params, const std::string& key) {
  const std::string k = underscored(key);
  for (const auto& spec : param_specs()) {
    if (spec.key != k || spec.scope == ParamScope::common) continue;
    const Method owner = spec.scope == ParamScope::paper ? Method::paper : Method::robust;
    if (owner == params.method) return {};
    return k + " belongs to the " + to_string(owner) + " method; the " + to_string(params.method) +
           " method ignores it";
  }
  return {};
}

std::string params_json(const Params& params) {
  std::string out = "{";
  bool first = true;
  for (const auto& spec : param_specs()) {
    out += (first ? "\"" : ",\"") + spec.key + "\":" + spec.json(params);
    first = false;
  }
  return out + "}";
}

}  // namespace groovetrace
