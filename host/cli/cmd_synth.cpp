// `groovetrace synth`: render a synthetic D415 scan and write it with its ground truth.

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <groovetrace/error.hpp>
#include <groovetrace/synth.hpp>
#include <memory>
#include <string>

#include "commands.hpp"

namespace groovetrace::cli {
namespace {

// Flags are taken as strings and converted here, so that every bad value is a
// groovetrace::UsageError (one line, exit 2) rather than a CLI11 conversion error.
struct SynthOptions {
  std::string shape, seed, width, height, resolution, distance, tilt, roll;
  std::string groove_width, groove_angle, groove_depth, root_gap, noise = "on", effects = "all";
  std::string depth_unit, output;
  std::string joint, misalignment, tacks, tack_height, clamps, clutter, pipe_diameter;
};

double to_double(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    throw UsageError("synth: " + flag + " expects a number, got '" + text + "'");
  return v;
}

long long to_integer(const std::string& flag, const std::string& text) {
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0')
    throw UsageError("synth: " + flag + " expects an integer, got '" + text + "'");
  return v;
}

int to_count(const std::string& flag, const std::string& text) {
  const long long v = to_integer(flag, text);
  if (v < 0 || v > 1000)
    throw UsageError("synth: " + flag + " expects a small count, got '" + text + "'");
  return static_cast<int>(v);
}

// Issue 12's joints and conditions.
void joint_params(const SynthOptions& o, SynthParams& p) {
  if (!o.joint.empty()) p.joint = parse_joint(o.joint);
  // A single bevel's usual angle; the V's default (60 deg) would make it 17 mm deep.
  if (p.joint == JointType::kBevel && o.groove_angle.empty() && o.groove_depth.empty())
    p.groove_angle_deg = 45.0;
  if (!o.misalignment.empty()) p.misalignment = to_double("--misalignment", o.misalignment);
  if (!o.tacks.empty()) p.tacks = to_count("--tacks", o.tacks);
  if (!o.tack_height.empty()) p.tack_height_fraction = to_double("--tack-height", o.tack_height);
  if (!o.clamps.empty()) p.clamps = to_count("--clamps", o.clamps);
  if (!o.clutter.empty()) p.clutter = to_count("--clutter", o.clutter);
  if (!o.pipe_diameter.empty()) p.pipe_diameter = to_double("--pipe-diameter", o.pipe_diameter);
}

SynthParams to_params(const SynthOptions& o) {
  SynthParams p;
  p.shape = parse_shape(o.shape);
  if (!o.seed.empty()) {
    char* end = nullptr;
    const unsigned long long seed = std::strtoull(o.seed.c_str(), &end, 10);
    if (*end != '\0' || o.seed[0] == '-')
      throw UsageError("synth: --seed expects a non-negative integer, got '" + o.seed + "'");
    p.seed = seed;
  }
  if (!o.resolution.empty()) {
    if (!o.width.empty() || !o.height.empty())
      throw UsageError("synth: give either --resolution or --width/--height, not both");
    const auto x = o.resolution.find('x');
    if (x == std::string::npos)
      throw UsageError("synth: --resolution expects WIDTHxHEIGHT, got '" + o.resolution + "'");
    p.width = static_cast<int>(to_integer("--resolution", o.resolution.substr(0, x)));
    p.height = static_cast<int>(to_integer("--resolution", o.resolution.substr(x + 1)));
  } else if (!o.width.empty() || !o.height.empty()) {
    if (o.width.empty() || o.height.empty())
      throw UsageError("synth: --width and --height go together");
    p.width = static_cast<int>(to_integer("--width", o.width));
    p.height = static_cast<int>(to_integer("--height", o.height));
  }
  if (!o.distance.empty()) p.distance = to_double("--distance", o.distance);
  if (!o.tilt.empty()) p.tilt_deg = to_double("--tilt", o.tilt);
  if (!o.roll.empty()) p.roll_deg = to_double("--roll", o.roll);
  if (!o.groove_width.empty()) p.groove_width = to_double("--groove-width", o.groove_width);
  if (!o.groove_angle.empty()) p.groove_angle_deg = to_double("--groove-angle", o.groove_angle);
  if (!o.groove_depth.empty()) {
    if (!o.groove_angle.empty())
      throw UsageError("synth: give either --groove-angle or --groove-depth, not both");
    p.groove_depth = to_double("--groove-depth", o.groove_depth);
    if (p.groove_depth <= 0.0) throw UsageError("synth: --groove-depth must be positive");
  }
  if (!o.root_gap.empty()) p.root_gap = to_double("--root-gap", o.root_gap);
  if (o.noise == "on")
    p.noise = true;
  else if (o.noise == "off")
    p.noise = false;
  else
    throw UsageError("synth: --noise expects on or off, got '" + o.noise + "'");
  p.effects = parse_effects(o.effects);
  if (!o.depth_unit.empty()) p.depth_unit = to_double("--depth-unit", o.depth_unit);
  joint_params(o, p);
  validate(p);
  return p;
}

}  // namespace

Command add_synth_command(CLI::App& app) {
  auto o = std::make_shared<SynthOptions>();
  CLI::App* sub = app.add_subcommand(
      "synth", "Render a synthetic RealSense D415 scan of a workpiece, with ground truth");
  std::string shapes;
  for (const std::string& n : shape_names()) shapes += (shapes.empty() ? "" : "|") + n;
  sub->add_option("--shape", o->shape, "Workpiece: " + shapes)->required();
  sub->add_option("--seed", o->seed, "Random seed (default 1); same seed, same bytes");
  sub->add_option("--resolution", o->resolution,
                  "WIDTHxHEIGHT: 1280x720 (default), 848x480, 640x480");
  sub->add_option("--width", o->width, "Image columns (with --height)");
  sub->add_option("--height", o->height, "Image rows (with --width)");
  sub->add_option("--distance", o->distance, "Camera to the seam's top centre, m (default 0.40)");
  sub->add_option("--tilt", o->tilt, "Camera pitch across the seam, deg (default 0)");
  sub->add_option("--roll", o->roll, "Camera roll about its optical axis, deg (default 0)");
  sub->add_option("--groove-width", o->groove_width, "Groove top width, m (default 0.010)");
  sub->add_option("--groove-angle", o->groove_angle,
                  "Included angle between the walls, deg (default 60; bevel 45)");
  sub->add_option("--groove-depth", o->groove_depth, "Depth of the V, m (instead of the angle)");
  sub->add_option("--root-gap", o->root_gap, "Root gap, m (default 0.0005)");
  sub->add_option("--noise", o->noise, "Sensor model on|off (default on)");
  sub->add_option("--effects", o->effects,
                  "Sensor effects when noise is on: all (default), none, or a list of "
                  "depth,undulation,blur,flying,grazing,shadow,band,dropout,minz,quantize");
  sub->add_option("--depth-unit", o->depth_unit,
                  "Depth quantisation, m: 0.001 (default) or 0.0001");
  sub->add_option("--joint", o->joint, "Joint: v (default), bevel, fillet (T-joint), lap");
  sub->add_option("--misalignment", o->misalignment,
                  "High-low: the +y part's top this much higher, m (default 0; 0-0.005)");
  sub->add_option("--tacks", o->tacks, "Tack welds per seam, in view (default 0; 0-10)");
  sub->add_option("--tack-height", o->tack_height,
                  "Tack height as a fraction of the joint depth (default 0.7; 0.1-1)");
  sub->add_option("--clamps", o->clamps, "Clamps on the plates beside the seam (default 0; 0-4)");
  sub->add_option("--clutter", o->clutter,
                  "Loose 20x20x150 mm bars on the table beside the part (default 0; 0-2)");
  sub->add_option("--pipe-diameter", o->pipe_diameter,
                  "Outer diameter of cylinder and pipe-long, m (default 0.10; 0.06-0.20)");
  sub->add_option("-o,--output", o->output, "Output scan SCAN.pcd (truth files beside it)")
      ->required();

  return {sub, [o]() {
            const SynthParams params = to_params(*o);
            const SynthFiles names = synth_files(o->output);
            const auto start = std::chrono::steady_clock::now();
            const SynthScan scan = render(params);
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
            const SynthFiles files = write_synth_scan(scan, names.scan);
            std::size_t labelled = 0;
            for (std::size_t i = 0; i < scan.truth.label.size(); ++i)
              labelled += scan.truth.label[i] && scan.truth.valid[i] ? 1 : 0;
            std::printf(
                "synth: %s %dx%d seed %llu: %zu of %zu points valid, %zu groove; "
                "rendered in %.0f ms\n",
                shape_name(params.shape), params.width, params.height,
                static_cast<unsigned long long>(params.seed), scan.cloud.count_valid(),
                scan.cloud.size(), labelled, ms);
            std::printf("wrote %s, %s, %s\n", files.scan.c_str(), files.truth.c_str(),
                        files.labels.c_str());
            return 0;
          }};
}

}  // namespace groovetrace::cli
