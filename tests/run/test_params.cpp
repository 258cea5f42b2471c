// The parameter table: each key writes its own method's field, reports the other method's
// keys, and round-trips through report.json's text; config files the fuzzer found mishandled.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <groovetrace/config.hpp>
#include <groovetrace/error.hpp>
#include <groovetrace/pipeline.hpp>
#include <nlohmann/json.hpp>
#include <set>

namespace groovetrace {
namespace {

TEST(Params, MethodIsAnEnumWithItsCliName) {
  Params p;
  EXPECT_EQ(p.method, Method::robust);
  set_param(p, "method", "paper");
  EXPECT_EQ(p.method, Method::paper);
  EXPECT_STREQ(to_string(p.method), "paper");
  EXPECT_THROW(set_param(p, "method", "Paper"), UsageError);
}

TEST(Params, EachKeyWritesItsOwnMethodsField) {
  Params p;
  EXPECT_EQ(p.paper.slices, 50);
  EXPECT_EQ(p.robust.slices, 0);  // the robust method spaces waypoints by `step` unless asked
  set_param(p, "radius", "0.004");
  set_param(p, "step", "0.003");
  set_param(p, "max-seams", "2");
  set_param(p, "weld_speed", "0.01");
  EXPECT_DOUBLE_EQ(p.paper.radius, 0.004);
  EXPECT_DOUBLE_EQ(p.robust.step, 0.003);
  EXPECT_EQ(p.robust.max_seams, 2);
  EXPECT_DOUBLE_EQ(p.program.weld_speed, 0.01);
  set_param(p, "slices", "20");  // both methods cut waypoints by it when given
  EXPECT_EQ(p.paper.slices, 20);
  EXPECT_EQ(p.robust.slices, 20);
}

TEST(Params, OtherMethodsKeysAreNamed) {
  Params robust;
  EXPECT_EQ(other_method_warning(robust, "threshold"),
            "threshold belongs to the paper method; the robust method ignores it");
  EXPECT_EQ(other_method_warning(robust, "mls-radius"),
            "mls_radius belongs to the paper method; the robust method ignores it");
  EXPECT_EQ(other_method_warning(robust, "step"), "");
  EXPECT_EQ(other_method_warning(robust, "slices"), "");
  EXPECT_EQ(other_method_warning(robust, "weld_speed"), "");
  Params paper;
  paper.method = Method::paper;
  EXPECT_EQ(other_method_warning(paper, "max_seams"),
            "max_seams belongs to the robust method; the paper method ignores it");
  EXPECT_EQ(other_method_warning(paper, "radius"), "");
}

TEST(Params, JsonNamesEveryKeyOnceAndValidates) {
  Params p;
  set_param(p, "threshold", "auto");
  set_param(p, "viewpoint", "0.1,0.2,0.3");
  const auto j = nlohmann::json::parse(params_json(p));
  std::set<std::string> keys;
  for (const auto& spec : param_specs()) {
    EXPECT_TRUE(keys.insert(spec.key).second) << spec.key;
    EXPECT_TRUE(j.contains(spec.key)) << spec.key;
  }
  EXPECT_EQ(j.size(), keys.size());
  EXPECT_EQ(j["threshold"], "auto");
  EXPECT_EQ(j["method"], "robust");
  EXPECT_NO_THROW(validate(p));
}

TEST(Params, ValidateRefusesWhatTheFlagsWould) {
  Params p;
  p.robust.slices = 1;  // set from code, below the flag's range
  EXPECT_THROW(validate(p), UsageError);
  Params q;
  q.paper.radius = 3.0;  // metres: meant as mm
  EXPECT_THROW(validate(q), UsageError);
  Params r;
  r.hand_eye_file = "hand_eye.yaml";  // without the flange pose
  EXPECT_THROW(validate(r), UsageError);
}

// A config file of this text in the test's temp dir; its path.
std::string config_file(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::path(::testing::TempDir()) / ("groovetrace_cfg_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

// The error apply_config_file throws for `text` in a file called `name`, checked to be of
// type E and one line; "" if it throws nothing.
template <class E>
std::string config_error(const std::string& name, const std::string& text) {
  Params p;
  try {
    apply_config_file(p, config_file(name, text));
  } catch (const E& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find_first_of("\r\n"), std::string::npos) << what;
    return what;
  }
  return "";
}

TEST(ConfigFile, AMapAsAValueIsAUsageError) {
  // fuzz_config_yaml: yaml-cpp's InvalidNode escaped (exit 5) when a value was a map.
  EXPECT_NE(config_error<UsageError>("map.yaml", "slices:\n  a: 1\n")
                .find("slices must be a value or a list of values"),
            std::string::npos);
}

TEST(ConfigFile, APathThatIsNotUtf8StillMakesJson) {
  // fuzz_config_yaml: nlohmann's type_error on the invalid byte escaped validate (exit 5).
  Params p;
  apply_config_file(p, config_file("bytes.yaml", "hand_eye: he\xff.yaml\nflange_pose: fp.yaml\n"));
  EXPECT_EQ(std::filesystem::path(p.hand_eye_file).filename(), "he\xff.yaml");
  EXPECT_NO_THROW(validate(p));
  // report.json shows the path absolute, taken from the config file's folder.
  const std::string folder =
      std::filesystem::path(::testing::TempDir()).lexically_normal().string();
  EXPECT_EQ(nlohmann::json::parse(params_json(p))["hand_eye"],
            (std::filesystem::path(folder) / "he\xef\xbf\xbd.yaml").string());
}

TEST(ConfigFile, ErrorsQuotingTheFileStayOneLine) {
  // fuzz_config_yaml: a value or key with a line break in it broke the one-line message.
  EXPECT_NE(config_error<UsageError>("nl.yaml", "radius: \"1\\n2\"\n").find("radius"),
            std::string::npos);
  EXPECT_NE(config_error<UsageError>("nl.json", "{\"a\\nb\": 1}").find("unknown parameter 'a?b'"),
            std::string::npos);
}

TEST(ConfigFile, AViewpointBeyondAKilometreIsRefused) {
  // fuzz_config_yaml: a viewpoint of 1.1e97 m, finite as a double, became inf in the float it
  // is kept in; validate refused it, but params_json printed it as "inf", which is not JSON.
  // A viewpoint is bounded as a scan's points are (1000 m, in metres whatever the units).
  const std::string far = "0,1" + std::string(96, '1') + "0,0.1";
  const std::string what =
      config_error<UsageError>("far.yaml", "viewpoint: \"" + far + "\"\nunits: mm\n");
  EXPECT_NE(what.find("viewpoint: 1111"), std::string::npos) << what;
  EXPECT_NE(what.find("out of range [-1000, 1000] m"), std::string::npos) << what;
  // What the file set before the error is what a run would report: still JSON.
  Params p;
  EXPECT_THROW(apply_config_file(p, config_file("far2.yaml", "viewpoint: \"" + far + "\"\n")),
               UsageError);
  EXPECT_TRUE(nlohmann::json::accept(params_json(p))) << params_json(p);
  EXPECT_THROW(set_param(p, "viewpoint", "0,-1000.5,0"), UsageError);
  set_param(p, "viewpoint", "-1000,0,1000");
  EXPECT_NO_THROW(validate(p));
}

// Set from code, a non-finite value is null in the parameters' JSON (as in report.json's other
// numbers), and validate still refuses it.
TEST(Params, NonFiniteValuesAreNullAndRefused) {
  Params p;
  p.viewpoint = Eigen::Vector3f(INFINITY, 0, 0);
  p.paper.radius = NAN;
  const auto j = nlohmann::json::parse(params_json(p));
  EXPECT_TRUE(j["viewpoint"][0].is_null()) << j["viewpoint"];
  EXPECT_TRUE(j["radius"].is_null()) << j["radius"];
  EXPECT_THROW(validate(p), UsageError);
  Params q;
  q.paper.radius = INFINITY;
  EXPECT_THROW(validate(q), UsageError);
}

TEST(ConfigFile, PathsAreTheConfigFilesFolders) {
  const auto sub = (std::filesystem::path(::testing::TempDir()) / "groovetrace_cfg_sub" / "cell")
                       .lexically_normal();
  std::filesystem::create_directories(sub);
  const auto cfg = sub / "run.yaml";
  std::ofstream(cfg) << "hand_eye: calib/he.yaml\nflange_pose: /abs/fp.txt\n";
  Params p;
  apply_config_file(p, cfg.string());
  EXPECT_EQ(p.hand_eye_file, (sub / "calib" / "he.yaml").string());
  EXPECT_EQ(p.flange_pose_file, "/abs/fp.txt");  // absolute: kept
  // A config named relatively (no folder): the path stays relative to the same folder, the
  // working directory.
  Params q;
  const auto cwd = std::filesystem::current_path();
  std::filesystem::current_path(sub);
  apply_config_file(q, "run.yaml");
  std::filesystem::current_path(cwd);
  EXPECT_EQ(q.hand_eye_file, "calib/he.yaml");
  // JSON too, and a flag is not a config: set_param keeps its path as given.
  const auto json = sub / "run.json";
  std::ofstream(json) << R"({"hand_eye": "../he.json", "flange_pose": "fp.json"})";
  Params r;
  apply_config_file(r, json.string());
  EXPECT_EQ(r.hand_eye_file, (sub.parent_path() / "he.json").string());
  EXPECT_EQ(r.flange_pose_file, (sub / "fp.json").string());
  set_param(r, "hand_eye", "x/he.yaml");
  EXPECT_EQ(r.hand_eye_file, "x/he.yaml");
}

TEST(ConfigFile, NullUnsetsOptionalValuesOnly) {
  Params p;
  set_param(p, "viewpoint", "0,0,1");
  set_param(p, "slices", "20");
  set_param(p, "hand_eye", "he.yaml");
  apply_config_file(
      p, config_file("nulls.json", R"({"viewpoint": null, "slices": null, "hand_eye": null})"));
  EXPECT_FALSE(p.viewpoint.has_value());
  EXPECT_EQ(p.paper.slices, 50);
  EXPECT_EQ(p.robust.slices, 0);
  EXPECT_EQ(p.hand_eye_file, "");
  Params q;
  set_param(q, "viewpoint", "0,0,1");
  apply_config_file(q, config_file("nulls.yaml", "viewpoint: null\nflange_pose: ~\nslices:\n"));
  EXPECT_FALSE(q.viewpoint.has_value());
  EXPECT_NE(config_error<UsageError>("null_speed.json", R"({"weld_speed": null})")
                .find(": weld_speed: null is no value here"),
            std::string::npos);
  EXPECT_NE(config_error<UsageError>("null_key.yaml", "no_such_key: null\n")
                .find("unknown parameter 'no_such_key'"),
            std::string::npos);
}

TEST(Params, JsonShowsTheChosenMethodsSlices) {
  Params robust;
  EXPECT_EQ(nlohmann::json::parse(params_json(robust))["slices"], nullptr);  // robust: step
  Params paper;
  paper.method = Method::paper;
  EXPECT_EQ(nlohmann::json::parse(params_json(paper))["slices"], 50);
  set_param(robust, "slices", "30");
  EXPECT_EQ(nlohmann::json::parse(params_json(robust))["slices"], 30);
}

// report.json's parameters, fed back, give the same Params: every spec's value, both methods,
// with and without the optional ones. The report itself is a config file too.
TEST(ConfigFile, ReportParametersGiveTheSameParams) {
  Params a;
  Params b;
  b.method = Method::paper;
  set_param(b, "viewpoint", "0.1,-0.2,0.3");
  set_param(b, "threshold", "auto");
  set_param(b, "slices", "40");
  set_param(b, "units", "mm");
  set_param(b, "hand_eye", "he.yaml");
  set_param(b, "flange_pose", "/abs/fp.yaml");
  Params c;
  set_param(c, "slices", "25");
  set_param(c, "step", "0.003");
  set_param(c, "smooth", "false");
  for (const Params* given : {&a, &b, &c}) {
    const std::string json = params_json(*given);
    const std::string report =
        R"({"version": "x", "status": "ok", "exit_code": 0, "parameters": )" + json + "}";
    for (const auto& [name, text] :
         {std::pair<std::string, std::string>{"params.json", json}, {"report.json", report}}) {
      Params back;
      back.robust.slices = 7;  // to be overwritten: null must unset it
      const auto keys = apply_config_file(back, config_file(name, text));
      EXPECT_EQ(params_json(back), json) << name;
      EXPECT_EQ(back.robust.slices, given->robust.slices) << name;
      EXPECT_EQ(back.paper.slices, given->paper.slices) << name;
      EXPECT_EQ(back.viewpoint.has_value(), given->viewpoint.has_value()) << name;
      // Only keys away from their defaults count (no warning for the other method's).
      for (const auto& k : keys) {
        EXPECT_NE(k, "radius") << name;
        EXPECT_NE(k, "max_seams") << name;
      }
    }
  }
  EXPECT_NE(config_error<InputError>("failed.json", R"({"status": "invalid_input", "exit_code": 3,)"
                                                    R"( "message": "x", "outputs": []})")
                .find("is a groovetrace report without parameters"),
            std::string::npos);
}

}  // namespace
}  // namespace groovetrace
