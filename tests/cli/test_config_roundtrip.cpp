// Parameters around a run: --help shows every default, a config file's paths are its folder's,
// report.json given back as --config runs the same, and a calibration file that cannot be
// used stops the run (exit 3) before any output.
#include <gtest/gtest.h>

#include <algorithm>
#include <groovetrace/config.hpp>
#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

std::string dashed(std::string key) {
  for (char& c : key) c = c == '_' ? '-' : c;
  return key;
}

// The help text of one flag: from "--key " to the next option line.
std::string flag_help(const std::string& help, const std::string& key) {
  const auto at = help.find("--" + dashed(key) + " ");
  if (at == std::string::npos) return "";
  return help.substr(at, help.find("\n  -", at) - at);
}

TEST(CliHelp, EveryParameterShowsItsDefault) {
  const fs::path dir = test::fresh_dir("help_defaults");
  for (const char* command : {"run", "batch"}) {
    SCOPED_TRACE(command);
    const auto r = test::run_cli(std::string(command) + " --help", dir);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    // A few by hand (params.hpp's defaults), then every spec against its report.json value.
    EXPECT_NE(flag_help(r.out, "weld_speed").find("(m/s) [default: 0.008]"), std::string::npos)
        << flag_help(r.out, "weld_speed");
    EXPECT_NE(flag_help(r.out, "approach_offset").find("[default: 0.05]"), std::string::npos);
    EXPECT_NE(flag_help(r.out, "blend_radius").find("[default: 0.002]"), std::string::npos);
    EXPECT_NE(flag_help(r.out, "arc_output").find("[default: 0]"), std::string::npos);
    EXPECT_NE(flag_help(r.out, "method").find("[default: robust]"), std::string::npos);
    EXPECT_NE(flag_help(r.out, "viewpoint").find("[default: none]"), std::string::npos);
    for (const auto& spec : param_specs()) {
      const auto value = nlohmann::json::parse(spec.json(Params()));
      std::string shown = value.is_string() ? value.get<std::string>() : value.dump();
      if (value.is_null() || shown.empty()) shown = "none";
      EXPECT_NE(flag_help(r.out, spec.key).find("[default: " + shown + "]"), std::string::npos)
          << spec.key << ": " << flag_help(r.out, spec.key);
    }
  }
}

class CliConfig : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    scan_ = dir_ / "scan.pcd";
    const auto s = test::run_cli(
        "synth --shape straight --resolution 320x240 --seed 5 -o " + scan_.string(), dir_);
    ASSERT_EQ(s.exit_code, 0) << s.err;
    // Calibration in two of the formats people have: a UR flange pose and a 4x4 matrix.
    fs::create_directories(dir_ / "calib");
    std::ofstream(dir_ / "calib" / "flange.txt") << "p[0.4, -0.1, 0.6, 0, 3.14159, 0]\n";
    std::ofstream(dir_ / "calib" / "hand_eye.txt") << "1 0 0 0.03\n0 1 0 0\n0 0 1 0.12\n0 0 0 1\n";
  }
  // `groovetrace ARGS` run from `cwd`.
  test::CliResult run_in(const fs::path& cwd, const std::string& args) const {
    return test::run_cli_command(
        "cd '" + cwd.string() + "' && " + std::string(GT_CLI_PATH) + " " + args, dir_);
  }
  fs::path dir_, scan_;
};

// Every output equal byte for byte; report.json equal but for its timings.
void expect_same_outputs(const fs::path& a, const fs::path& b) {
  EXPECT_EQ(test::entries(a), test::entries(b));
  for (const auto& name : test::entries(a)) {
    const std::string ta = test::read_text(a / name), tb = test::read_text(b / name);
    if (name != "report.json") {
      EXPECT_TRUE(ta == tb) << name << " differs";
      continue;
    }
    auto ja = nlohmann::json::parse(ta), jb = nlohmann::json::parse(tb);
    ja.erase("timings_ms");
    jb.erase("timings_ms");
    EXPECT_TRUE(ja == jb) << "report.json differs beyond its timings: " << ja["parameters"].dump()
                          << " vs " << jb["parameters"].dump();
  }
}

TEST_F(CliConfig, ReportAsConfigRunsTheSame) {
  // The first run takes its calibration from a config file in another folder, by paths
  // relative to that file, from a third working directory.
  fs::create_directories(dir_ / "cfg");
  fs::create_directories(dir_ / "elsewhere");
  std::ofstream(dir_ / "cfg" / "cell.yaml")
      << "hand_eye: ../calib/hand_eye.txt\nflange_pose: ../calib/flange.txt\n";
  for (const std::string method : {"robust", "paper"}) {
    SCOPED_TRACE(method);
    const fs::path first = dir_ / ("first_" + method), again = dir_ / ("again_" + method),
                   params = dir_ / ("params_" + method + ".json");
    const std::string extra = method == "paper" ? " --slices 30 --viewpoint 0,0,0.01" : "";
    auto r = run_in(dir_ / "elsewhere", "run " + scan_.string() + " -q --backend cpu --method " +
                                            method + extra + " --config ../cfg/cell.yaml -o " +
                                            first.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const auto report = nlohmann::json::parse(test::read_text(first / "report.json"));
    EXPECT_EQ(report["trajectory"]["frame"], "base");
    EXPECT_EQ(report["parameters"]["hand_eye"], (dir_ / "calib" / "hand_eye.txt").string());
    EXPECT_EQ(report["parameters"]["slices"],
              method == "paper" ? nlohmann::json(30) : nlohmann::json(nullptr));
    const auto other_method = [](const std::string& text) {
      return text.find("method ignores it") != std::string::npos;
    };
    EXPECT_FALSE(other_method(report["warnings"].dump())) << report["warnings"];

    // The report itself, and its parameters alone, as --config, from yet another directory.
    r = run_in(dir_, "run " + scan_.string() + " -q --backend cpu --config " +
                         (first / "report.json").string() + " -o " + again.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_FALSE(other_method(r.err)) << r.err;  // the other method's keys are at defaults
    expect_same_outputs(first, again);
    std::ofstream(params) << report["parameters"].dump();
    fs::remove_all(again);
    r = run_in(dir_ / "calib", "run " + scan_.string() + " -q --backend cpu --config " +
                                   params.string() + " -o " + again.string());
    ASSERT_EQ(r.exit_code, 0) << r.err;
    expect_same_outputs(first, again);
  }
}

TEST_F(CliConfig, ACalibrationFileThatCannotBeUsedStopsTheRun) {
  std::ofstream(dir_ / "calib" / "ambiguous.yaml")
      << "translation: [0, 0, 0.1]\nquaternion: [0.1, 0.2, 0.3, 0.9273618495495703]\n";
  const fs::path out = dir_ / "out";
  const auto r = test::run_cli("run " + scan_.string() + " -q --backend cpu -o " + out.string() +
                                   " --hand-eye " + (dir_ / "calib" / "ambiguous.yaml").string() +
                                   " --flange-pose " + (dir_ / "calib" / "flange.txt").string(),
                               dir_);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err.rfind("groovetrace: error: " + (dir_ / "calib" / "ambiguous.yaml").string() +
                            ": 'quaternion' is a quaternion of 4 numbers that does not say its "
                            "order",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  test::expect_failure_report(out, 3, r.err);
}

}  // namespace
}  // namespace groovetrace
