#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <limits>
#include <nlohmann/json.hpp>
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

std::string num(double v) {
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
ParamSpec choice(const std::string& key, const std::string& help, std::string Params::*field,
                 std::vector<std::string> allowed) {
  return {key, help, ParamScope::common,
          [=](Params& p, const std::string& t) { p.*field = one_of(key, t, allowed); },
          [=](const Params& p) { return quoted(p.*field); }};
}
ParamSpec path(const std::string& key, const std::string& help, std::string Params::*field) {
  return {
      key, help, ParamScope::common,
      [=](Params& p, const std::string& t) {
        if (trim(t).empty()) throw UsageError(key + ": expected a file path");
        p.*field = t;
      },
      [=](const Params& p) { return (p.*field).empty() ? std::string("null") : quoted(p.*field); }};
}

Eigen::Vector3f parse_viewpoint(const std::string& t) {
  std::stringstream ss(t);
  std::string part;
  std::vector<double> v;
  while (std::getline(ss, part, ',')) v.push_back(parse_number("viewpoint", part));
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
               "OpenCL device: its index N or part of its name; default: first GPU, "
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
// else `step`), so it sets both; report.json shows the paper method's value.
void add_waypoint_specs(std::vector<ParamSpec>& s) {
  constexpr auto kRobust = ParamScope::robust;
  constexpr auto kPaper = ParamScope::paper;
  s.push_back({"slices",
               "slices along the groove, one waypoint each (robust: given, it wins over step)",
               ParamScope::common,
               [](Params& p, const std::string& t) {
                 p.paper.slices = p.robust.slices = int_in_range("slices", t, 2, 100000);
               },
               [](const Params& p) { return std::to_string(p.paper.slices); }});
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

// The robot program (URScript).
void add_program_specs(std::vector<ParamSpec>& s) {
  constexpr auto kCommon = ParamScope::common;
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
  s.push_back(integer(kCommon, "arc_output", "standard digital output that switches the arc",
                      program(&ProgramParams::arc_output), 0, 7));
  s.push_back(real(kCommon, "arc_delay", "wait after arc on", program(&ProgramParams::arc_delay),
                   0.0, 60.0, "s"));
}

std::vector<ParamSpec> build_specs() {
  std::vector<ParamSpec> s;
  add_common_specs(s);
  add_paper_specs(s);
  s.push_back({"viewpoint",
               "sensor origin X,Y,Z in the cloud's frame (m); default: PCD "
               "VIEWPOINT, else the origin",
               ParamScope::common,
               [](Params& p, const std::string& t) { p.viewpoint = parse_viewpoint(t); },
               viewpoint_json});
  add_detection_specs(s);
  add_waypoint_specs(s);
  add_program_specs(s);
  s.push_back(
      path("hand_eye", "T_flange_camera file (YAML/JSON, docs/frames.md)", &Params::hand_eye_file));
  s.push_back(path("flange_pose", "T_base_flange at capture (YAML/JSON, docs/frames.md)",
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

// A YAML key for a message: its text, or "a key" when it is no scalar.
std::string shown_key(const YAML::Node& key) {
  return key.IsScalar() ? io::shown(key.Scalar(), 100) : std::string("a key");
}

}  // namespace

std::vector<std::string> apply_config_file(Params& params, const std::string& path) {
  const std::string text = io::read_all(path, true);
  io::require_shallow(text, path);
  std::vector<std::pair<std::string, std::string>> entries;
  const auto dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".json") {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
      throw InputError("config file " + path + " is not valid JSON");
    }
    if (!j.is_object()) throw InputError("config file " + path + " must hold a JSON object");
    for (const auto& [k, v] : j.items()) {
      if (v.is_string()) {
        entries.emplace_back(k, v.get<std::string>());
      } else if (v.is_array()) {
        std::string joined;
        for (const auto& e : v) joined += (joined.empty() ? "" : ",") + e.dump();
        entries.emplace_back(k, joined);
      } else {
        entries.emplace_back(k, v.dump());
      }
    }
  } else if (ext == ".yaml" || ext == ".yml") {
    YAML::Node root;
    try {
      root = YAML::Load(text);
    } catch (const std::exception& e) {
      throw InputError("config file " + path + " is not valid YAML");
    }
    if (root.IsNull()) return {};
    if (!root.IsMap()) throw InputError("config file " + path + " must hold a YAML map");
    for (const auto& kv : root) {
      // A key or list element that is itself a list or map is no value (yaml-cpp's "bad
      // conversion" was exit 5). Only a list is searched for them: a map's entries are no
      // nodes, and asking one IsScalar() threw YAML::InvalidNode (exit 5 too).
      const bool scalars =
          kv.second.IsSequence() && std::all_of(kv.second.begin(), kv.second.end(),
                                                [](const YAML::Node& e) { return e.IsScalar(); });
      if (!kv.first.IsScalar() || !(kv.second.IsScalar() || scalars)) {
        throw UsageError("config file " + path + ": " + shown_key(kv.first) +
                         " must be a value or a list of values");
      }
      const std::string k = kv.first.as<std::string>();
      if (kv.second.IsSequence()) {
        std::string joined;
        for (const auto& e : kv.second) joined += (joined.empty() ? "" : ",") + e.as<std::string>();
        entries.emplace_back(k, joined);
      } else {
        entries.emplace_back(k, kv.second.as<std::string>());
      }
    }
  } else {
    throw InputError("config file " + path + " must end in .yaml, .yml or .json");
  }
  std::vector<std::string> keys;
  for (const auto& [k, v] : entries) {
    try {
      set_param(params, k, v);
    } catch (const UsageError& e) {
      throw UsageError("config file " + path + ": " + e.what());
    }
    keys.push_back(underscored(k));
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
