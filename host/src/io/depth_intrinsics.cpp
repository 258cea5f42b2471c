// The intrinsics JSON of a depth PNG and where it is found (io/depth_png.hpp).
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <groovetrace/error.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "io/depth_png.hpp"
#include "io/text.hpp"

namespace groovetrace::io {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct Where {
  const std::string& path;
  [[noreturn]] void fail(const std::string& what) const {
    throw InputError("depth intrinsics " + shown(path) + ": " + what);
  }
};

double positive(const json& root, const char* key, const Where& where) {
  if (!root.contains(key)) where.fail(std::string("no '") + key + "' (required)");
  const json& v = root[key];
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() <= 0) {
    where.fail(std::string("'") + key + "' must be a positive number, got " + shown(v.dump(), 40));
  }
  return v.get<double>();
}

double finite(const json& root, const char* key, const Where& where) {
  if (!root.contains(key)) where.fail(std::string("no '") + key + "' (required)");
  const json& v = root[key];
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    where.fail(std::string("'") + key + "' must be a number, got " + shown(v.dump(), 40));
  }
  return v.get<double>();
}

std::uint32_t side(const json& root, const char* key, const Where& where) {
  if (!root.contains(key)) return 0;
  const json& v = root[key];
  const bool ok = v.is_number_integer() && v.get<long long>() >= 1 &&
                  v.get<long long>() <= static_cast<long long>(kMaxDepthSide);
  if (!ok) {
    where.fail(std::string("'") + key + "' must be an integer 1-" + std::to_string(kMaxDepthSide) +
               ", got " + shown(v.dump(), 40));
  }
  return static_cast<std::uint32_t>(v.get<long long>());
}

// librealsense's distortion models by name ("Brown Conrady", "distortion.brown_conrady",
// "RS2_DISTORTION_BROWN_CONRADY") or rs2_distortion value (0-5), as "none", "brown_conrady", ...
std::string model_name(const json& model, const Where& where) {
  static const char* const kByValue[] = {
      "none",   "modified_brown_conrady", "inverse_brown_conrady",
      "ftheta", "brown_conrady",          "kannala_brandt4"};
  if (model.is_number_integer()) {
    const long long v = model.get<long long>();
    if (v < 0 || v > 5) where.fail("unknown distortion model " + std::to_string(v));
    return kByValue[v];
  }
  if (!model.is_string()) where.fail("'model' must be a name or an rs2_distortion value");
  std::string name;
  for (char c : model.get<std::string>()) {
    name += c == ' ' ? '_' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  for (const char* prefix : {"rs2_distortion_", "distortion."}) {
    if (name.rfind(prefix, 0) == 0) name.erase(0, std::strlen(prefix));
  }
  return name;
}

// Depth is deprojected with the plain pinhole model: distortion other than none is refused.
// D4xx depth streams are rectified and report Brown-Conrady with all coefficients zero,
// which is no distortion; F-theta and Kannala-Brandt are not the identity even with zeros.
void check_distortion(const json& root, const Where& where) {
  const std::string model = root.contains("model") ? model_name(root["model"], where) : "none";
  const bool pinhole_family = model == "none" || model == "brown_conrady" ||
                              model == "modified_brown_conrady" || model == "inverse_brown_conrady";
  if (!pinhole_family) {
    where.fail("distortion model '" + shown(model, 40) +
               "' is not supported (only none, or Brown-Conrady with zero coefficients)");
  }
  if (!root.contains("coeffs")) return;
  const json& c = root["coeffs"];
  if (!c.is_array() || c.size() > 16) where.fail("'coeffs' must be a list of numbers");
  for (const json& k : c) {
    if (!k.is_number()) where.fail("'coeffs' must be a list of numbers");
    if (k.get<double>() != 0.0) {
      where.fail("distortion coefficients " + shown(c.dump(), 80) +
                 " are not zero: undistort the depth image first (only none is supported)");
    }
  }
}

}  // namespace

DepthIntrinsics parse_depth_intrinsics(const std::string& text, const std::string& path) {
  const Where where{path};
  require_shallow(text, path);
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    where.fail(std::string("not valid JSON (") + shown(e.what(), 200) + ")");
  }
  if (!root.is_object()) where.fail("expected a JSON object with fx, fy, ppx, ppy, depth_scale");
  DepthIntrinsics k;
  k.fx = positive(root, "fx", where);
  k.fy = positive(root, "fy", where);
  k.ppx = finite(root, "ppx", where);
  k.ppy = finite(root, "ppy", where);
  k.depth_scale = positive(root, "depth_scale", where);
  k.width = side(root, "width", where);
  k.height = side(root, "height", where);
  check_distortion(root, where);
  return k;
}

std::string find_depth_intrinsics(const std::string& png, const std::string& given) {
  if (!given.empty()) return given;
  const fs::path p(png);
  std::error_code ec;
  for (const fs::path& candidate :
       {p.parent_path() / (p.stem().string() + ".json"), p.parent_path() / "intrinsics.json"}) {
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  }
  return "";
}

}  // namespace groovetrace::io
