// Every bad input to `groovetrace run`: one line on stderr, the documented exit code, and
// OUTDIR holding only the report.json that says so.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <groovetrace/cloud_io.hpp>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

class BadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    out_ = dir_ / "out";
  }
  // Writes a small ascii PCD with the given header body and data lines.
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p;
  }
  fs::path good_scan() {
    test::VGrooveScene s;
    s.width = 160;
    s.height = 120;
    const fs::path p = dir_ / "good.pcd";
    write_file_atomic(p.string(), pcd_bytes(test::render_vgroove(s).cloud));
    return p;
  }
  // Runs `run <args> -o out` and checks the contract for a failure.
  void expect_failure(const std::string& args, int code, const std::string& phrase) {
    fs::remove_all(out_);  // what is there afterwards is this run's
    const auto r = test::run_cli("run " + args + " -o " + out_.string(), dir_);
    EXPECT_EQ(r.exit_code, code) << r.err;
    EXPECT_NE(r.err.find(phrase), std::string::npos) << "stderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "stderr: " << r.err;
    EXPECT_EQ(r.err.rfind("groovetrace: error: ", 0), 0u) << r.err;
    // A flag CLI11 refuses stops the run before it checks OUTDIR: nothing is written then.
    if (fs::exists(out_)) test::expect_failure_report(out_, code, r.err);
  }
  fs::path dir_, out_;
};

std::string ascii_pcd(const std::string& fields, int width, int height, const std::string& data) {
  std::string types, sizes, counts;
  std::stringstream ss(fields);
  std::string f;
  while (ss >> f) {
    types += " F";
    sizes += " 4";
    counts += " 1";
  }
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE" + sizes + "\nTYPE" + types +
         "\nCOUNT" + counts + "\nWIDTH " + std::to_string(width) + "\nHEIGHT " +
         std::to_string(height) + "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         std::to_string(width * height) + "\nDATA ascii\n" + data;
}

std::string rows(int n, const std::string& row) {
  std::string s;
  for (int i = 0; i < n; ++i) s += row + "\n";
  return s;
}

TEST_F(BadInput, MissingFile) { expect_failure((dir_ / "nope.pcd").string(), 3, "nope.pcd"); }

TEST_F(BadInput, DirectoryInsteadOfFile) {
  fs::create_directories(dir_ / "adir.pcd");
  expect_failure((dir_ / "adir.pcd").string(), 3, "adir.pcd");
}

TEST_F(BadInput, UnknownExtension) {
  expect_failure(write("scan.xyz", "1 2 3\n").string(), 3, "scan.xyz");
}

TEST_F(BadInput, GarbageFile) {
  expect_failure(write("garbage.pcd", "this is not a point cloud\n").string(), 3, "garbage.pcd");
}

TEST_F(BadInput, TruncatedBinaryPcd) {
  const std::string bytes = test::read_text(good_scan());
  expect_failure(write("cut.pcd", bytes.substr(0, bytes.size() / 2)).string(), 3, "cut.pcd");
}

TEST_F(BadInput, TruncatedAsciiPcd) {
  // Header promises 200 points, 120 are there.
  expect_failure(
      write("cut_ascii.pcd", ascii_pcd("x y z", 200, 1, rows(120, "0.1 0.2 0.5"))).string(), 3,
      "cut_ascii.pcd");
}

TEST_F(BadInput, NoXyzFields) {
  expect_failure(write("rgb.pcd", ascii_pcd("a b c", 200, 1, rows(200, "1 2 3"))).string(), 3,
                 "x/y/z");
}

TEST_F(BadInput, EmptyCloud) {
  expect_failure(write("empty.pcd", ascii_pcd("x y z", 0, 1, "")).string(), 3, "empty.pcd");
}

TEST_F(BadInput, AllNaN) {
  expect_failure(write("nan.pcd", ascii_pcd("x y z", 200, 1, rows(200, "nan nan nan"))).string(), 3,
                 "NaN");
}

TEST_F(BadInput, TooFewPoints) {
  expect_failure(write("few.pcd", ascii_pcd("x y z", 20, 1, rows(20, "0.1 0.2 0.5"))).string(), 3,
                 "few.pcd");
}

TEST_F(BadInput, InfiniteValues) {
  expect_failure(
      write("inf.pcd", ascii_pcd("x y z", 200, 1, rows(199, "0.1 0.2 0.5") + "inf 0.2 0.5\n"))
          .string(),
      3, "infinite");
}

// One point of a real scene at 1e8 m: the default path (OpenCL where there is a device)
// segfaulted in the crease kernel (exit 139); it is an input error now, like an infinity.
TEST_F(BadInput, PointBeyondAKilometre) {
  Cloud cloud = read_cloud(good_scan().string());
  cloud.x[5000] = 1e8f;
  const fs::path p = dir_ / "outlier.pcd";
  write_file_atomic(p.string(), pcd_bytes(cloud));
  expect_failure(p.string(), 3, "beyond 1000 m");
}

// The paper method's stages visit every neighbour of every point: 28,800 identical points
// took 20-46 s before failing with "no groove found". Too dense a scan is refused first.
TEST_F(BadInput, PaperMethodRefusesAScanTooDenseForItsRadius) {
  expect_failure(
      write("same.pcd", ascii_pcd("x y z", 28800, 1, rows(28800, "0.1 0.2 0.5"))).string() +
          " --method paper --backend cpu",
      3, "too dense for the paper method");
}

TEST_F(BadInput, NoGrooveOnAFlatPlate) {
  test::VGrooveScene s;
  s.width = 160;
  s.height = 120;
  s.depth = 1e-9;  // a V too shallow to see: a flat plate
  const fs::path p = dir_ / "flat.pcd";
  write_file_atomic(p.string(), pcd_bytes(test::render_vgroove(s).cloud));
  expect_failure(p.string() + " --backend cpu", 4, "no groove found");
}

TEST_F(BadInput, UnwritableOutputDirectory) {
  // A path below a regular file can never be created, even by root.
  const fs::path file = write("plainfile", "x");
  const auto r =
      test::run_cli("run " + good_scan().string() + " -o " + (file / "out").string(), dir_);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(BadInput, OutputPathIsAFile) {
  const fs::path file = write("outfile", "x");
  const auto r = test::run_cli("run " + good_scan().string() + " -o " + file.string(), dir_);
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("not a directory"), std::string::npos) << r.err;
  EXPECT_EQ(test::read_text(file), "x");  // untouched
}

struct FlagCase {
  const char* flags;
  const char* phrase;
};

TEST_F(BadInput, BadFlagValues) {
  const std::string scan = good_scan().string();
  const FlagCase cases[] = {
      {"--radius abc", "--radius"},
      {"--radius -1", "--radius"},
      {"--radius 3", "out of range"},
      {"--threshold high", "--threshold"},
      {"--slices 0", "--slices"},
      {"--slices 2.5", "integer"},
      {"--units km", "--units"},
      {"--backend gpu", "--backend"},
      {"--method magic", "--method"},
      {"--viewpoint 1,2", "--viewpoint"},
      {"--viewpoint 0,2000,0.1", "out of range [-1000, 1000] m"},
      {"--smooth maybe", "--smooth"},
      {"--no-such-flag 1", "no-such-flag"},
      {"--weld-speed 0", "--weld-speed"},
      {"--hand-eye he.yaml", "--flange-pose"},
      {"--orientation-blend -0.01", "--orientation-blend"},
      {"--orientation-blend nan", "--orientation-blend"},
      {"--orientation-blend wide", "--orientation-blend"},
      {"--fillet-leg 0", "--fillet-leg"},
      {"--fillet-leg 0.2", "out of range"},
      {"--fillet-leg leg", "--fillet-leg"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.flags);
    expect_failure(scan + " " + c.flags, 2, c.phrase);
  }
}

TEST_F(BadInput, MissingArguments) {
  const auto r = test::run_cli("run", dir_);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  const auto r2 = test::run_cli("frobnicate", dir_);
  EXPECT_EQ(r2.exit_code, 2);
}

TEST_F(BadInput, BadConfigFiles) {
  const std::string scan = good_scan().string();
  expect_failure(scan + " --config " + write("c1.yaml", "radius: [1, 2\n").string(), 3, "c1.yaml");
  expect_failure(scan + " --config " + write("c2.yaml", "radiuss: 0.003\n").string(), 2, "radiuss");
  expect_failure(scan + " --config " + write("c3.json", "{\"slices\": -4}").string(), 2, "slices");
  expect_failure(scan + " --config " + write("c4.yaml", "orientation_blend: -1\n").string(), 2,
                 "orientation_blend");
  expect_failure(scan + " --config " + (dir_ / "missing.yaml").string(), 3, "missing.yaml");
  // A list inside a list is no value (yaml-cpp's "bad conversion": exit 5 before).
  expect_failure(scan + " --config " + write("c5.yaml", "radius: [[0.003]]\n").string(), 2,
                 "radius must be a value");
  // 100,000 nested brackets overflowed the parser's stack: a segfault with nothing printed.
  const std::string deep(100000, '[');
  expect_failure(scan + " --config " + write("c6.yaml", "radius: " + deep).string(), 3,
                 "nests brackets deeper than 64");
  expect_failure(scan + " --config " + write("c7.json", "{\"radius\": " + deep).string(), 3,
                 "nests brackets deeper than 64");
  // fuzz_config_yaml: a viewpoint of 1.1e97 m became inf in its float, not JSON in the report.
  expect_failure(
      scan + " --config " +
          write("c10.yaml", "viewpoint: \"0,1" + std::string(96, '1') + "0,0.1\"\nunits: mm\n")
              .string(),
      2, "out of range [-1000, 1000] m");
  // Only regular files: a directory was silently ignored (exit 0), a FIFO hung the run.
  fs::create_directory(dir_ / "c8.yaml");
  expect_failure(scan + " --config " + (dir_ / "c8.yaml").string(), 3, "is a directory");
  ASSERT_EQ(::mkfifo((dir_ / "c9.yaml").c_str(), 0600), 0);
  expect_failure(scan + " --config " + (dir_ / "c9.yaml").string(), 3, "not a regular file");
}

TEST_F(BadInput, EmptyOutputPath) {
  // std::filesystem has no absolute form of "": exit 5, "internal", before.
  const auto r = test::run_cli("run " + good_scan().string() + " -o ''", dir_);
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("empty path"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(BadInput, BadCalibrationFiles) {
  const std::string scan = good_scan().string();
  const fs::path good = write("flange.yaml", "translation: [0, 0, 0.5]\nrotation: [0, 0, 0, 1]\n");
  const fs::path skew = write("he.yaml", "translation: [0, 0, 0.1]\nrotation: [0, 0, 0.5, 1]\n");
  expect_failure(scan + " --hand-eye " + skew.string() + " --flange-pose " + good.string(), 3,
                 "unit");
  expect_failure(
      scan + " --hand-eye " + (dir_ / "none.yaml").string() + " --flange-pose " + good.string(), 3,
      "none.yaml");
  // A translation of 1e300 m ran the scan and failed in the URScript writer (exit 5).
  const fs::path far = write("far.yaml", "translation: [1e300, 0, 0]\nrotation: [0, 0, 0, 1]\n");
  expect_failure(scan + " --hand-eye " + far.string() + " --flange-pose " + good.string(), 3,
                 "beyond the 1000 m");
  // A FIFO hung the read; deep nesting overflowed the parser's stack.
  ASSERT_EQ(::mkfifo((dir_ / "fifo.yaml").c_str(), 0600), 0);
  expect_failure(
      scan + " --hand-eye " + (dir_ / "fifo.yaml").string() + " --flange-pose " + good.string(), 3,
      "not a regular file");
  const fs::path deep = write("deep.json", "{\"translation\": " + std::string(100000, '['));
  expect_failure(scan + " --hand-eye " + deep.string() + " --flange-pose " + good.string(), 3,
                 "nests brackets deeper than 64");
}

}  // namespace
}  // namespace groovetrace
