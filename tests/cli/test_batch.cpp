// `groovetrace batch` and `groovetrace report` end to end: bad scans are rows, a crashing or
// hanging scan takes only its worker, a killed batch resumes, and the summary adds up.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <groovetrace/cloud_io.hpp>
#include <nlohmann/json.hpp>
#include <set>
#include <thread>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;

// Rows of summary.csv: dir -> status (the csv's second and third columns; no dir holds a comma).
std::map<std::string, std::string> statuses(const fs::path& csv) {
  std::map<std::string, std::string> out;
  std::istringstream in(test::read_text(csv));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    const auto a = line.find(','), b = line.find(',', a + 1), c = line.find(',', b + 1);
    out[line.substr(a + 1, b - a - 1)] = line.substr(b + 1, c - b - 1);
  }
  return out;
}

std::size_t count_files(const fs::path& dir, const std::string& suffix) {
  std::size_t n = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    n += name.size() >= suffix.size() &&
                 name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0
             ? 1
             : 0;
  }
  return n;
}

// scan.json (path -> text) of every whole scan directory under `out`; one still under .partial
// (between its files and its rename) is not done. Empty while the batch is still renaming:
// a directory that vanishes under the walk makes it throw.
std::map<std::string, std::string> done_scans(const fs::path& out) {
  std::map<std::string, std::string> done;
  try {
    if (!fs::exists(out)) return done;
    for (const auto& e : fs::recursive_directory_iterator(out)) {
      if (e.path().filename() == "scan.json" &&
          e.path().string().find("/.partial/") == std::string::npos) {
        done[e.path().string()] = test::read_text(e.path());
      }
    }
  } catch (const std::exception&) {
    return {};
  }
  return done;
}

// index.html as a person sees it: Chromium (Debian's, installed by scripts/setup.sh) loads it
// from the file system headless; returns the DOM after load and fills `log` with what the
// browser said (resource and script errors land there).
std::string browser_dom(const fs::path& html, const fs::path& scratch, std::string& log) {
  const fs::path profile = scratch / "chromium-profile";
  const auto r = test::run_cli_command(
      "chromium --headless --no-sandbox --disable-gpu --enable-logging=stderr --v=0 "
      "--user-data-dir=" +
          profile.string() + " --dump-dom file://" + html.string(),
      scratch);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  log = r.err;
  return r.out;
}

class CliBatch : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    in_ = dir_ / "scans";
    fs::create_directories(in_ / "line1");
    fs::create_directories(in_ / "line2");
  }
  // A rendered V-groove scan (test::repeated_run_scene), seeded so that each file differs.
  void write_scan(const fs::path& path, unsigned seed, double depth = 0.004) {
    test::VGrooveScene s = test::repeated_run_scene();
    s.tilt_deg = 5.0 + seed;
    s.noise_sigma = 0.0002;
    s.seed = seed;
    s.depth = depth;
    write_file_atomic(path.string(), pcd_bytes(test::render_vgroove(s).cloud));
  }
  std::string batch(const std::string& args) {
    return "batch " + in_.string() + " -o " + (dir_ / "out").string() + " --backend cpu " + args;
  }
  fs::path dir_, in_;
};

// The night in small: 20 synthetic scans (17 from the renderer, 3 rendered here) and
// four bad ones; with test::small_runs() 5 from the renderer (one per shape).
TEST_F(CliBatch, BadScansAreRowsAndTheBatchGoesOn) {
  std::map<std::string, std::string> expected;
  const char* shapes[] = {"straight", "curve", "lshape", "box", "cylinder"};
  const int n_synth = test::small_runs() ? 5 : 17;
  const int n_scans = n_synth + 7;
  fs::create_directories(in_ / "synth");
  for (int k = 0; k < n_synth; ++k) {
    const std::string name = std::string(shapes[k % 5]) + "-" + std::to_string(k);
    const auto synth = test::run_cli("synth --shape " + std::string(shapes[k % 5]) + " --seed " +
                                         std::to_string(k + 1) + " --resolution 640x480 -o " +
                                         (in_ / "synth" / (name + ".pcd")).string(),
                                     dir_);
    ASSERT_EQ(synth.exit_code, 0) << synth.err;
    expected["synth/" + name] = "ok";
  }
  write_scan(in_ / "line1" / "a.pcd", 1);
  write_scan(in_ / "line1" / "b.pcd", 2);
  write_scan(in_ / "line2" / "a.pcd", 3);          // same stem, other folder: no collision
  write_scan(in_ / "line2" / "flat.pcd", 4, 0.0);  // no groove
  write_scan(in_ / "line2" / "crash.pcd", 5);      // its worker raises SIGSEGV
  const std::string good = test::read_text(in_ / "line1" / "a.pcd");
  std::ofstream(in_ / "line2" / "truncated.pcd", std::ios::binary) << good.substr(0, 2000);
  std::ofstream(in_ / "line2" / "empty.pcd");
  const auto r = test::run_cli(batch("--jobs 2 --progress lines"), dir_,
                               "GROOVETRACE_TEST_CRASH_SCAN=crash.pcd");
  EXPECT_EQ(r.exit_code, 6) << r.err << r.out;  // docs/batch.md: some scan failed
  expected.insert({{"line1/a", "ok"},
                   {"line1/b", "ok"},
                   {"line2/a", "ok"},
                   {"line2/flat", "no_groove"},
                   {"line2/crash", "crashed"},
                   {"line2/truncated", "invalid_input"},
                   {"line2/empty", "invalid_input"}});
  ASSERT_EQ(expected.size(), static_cast<std::size_t>(n_scans));
  EXPECT_EQ(statuses(dir_ / "out" / "summary.csv"), expected);
  // One progress line per scan, and the scans after the crash still ran.
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), n_scans) << r.err;
  // No calibration files: the trajectory is in camera coordinates, so no program (docs/robot.md).
  EXPECT_FALSE(fs::exists(dir_ / "out" / "line2" / "a" / "program.script"));
  for (const char* f : {"trajectory.csv", "report.json", "scan.json"}) {
    EXPECT_TRUE(fs::exists(dir_ / "out" / "line2" / "a" / f)) << f;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out" / "line2" / "crash" / "trajectory.csv"));
  EXPECT_EQ(count_files(dir_ / "out", ".tmp"), 0u);
  EXPECT_FALSE(fs::exists(dir_ / "out" / ".partial"));
  const auto summary = nlohmann::json::parse(test::read_text(dir_ / "out" / "summary.json"));
  EXPECT_EQ(summary["scans"], n_scans);
  EXPECT_EQ(summary["ok"], n_synth + 3);
  const std::string html = test::read_text(dir_ / "out" / "index.html");
  for (const auto& [d, status] : expected) {
    EXPECT_NE(html.find("data-dir=\"" + d + "\""), std::string::npos) << d;
  }
  // The failures come first, with their messages.
  EXPECT_LT(html.find("Segmentation fault"), html.find("id=\"scans\""));

  // Chromium loads the page with no resource or script error, and it lists every scan.
  std::string log;
  const std::string dom = browser_dom(dir_ / "out" / "index.html", dir_, log);
  for (const auto& [d, status] : expected) {
    EXPECT_NE(dom.find("data-dir=\"" + d + "\""), std::string::npos) << d;
  }
  EXPECT_NE(dom.find(std::to_string(n_scans) + " scans"), std::string::npos);
  EXPECT_NE(dom.find("line1/a/thumbnail.png"), std::string::npos);  // the ok scans have pictures
  EXPECT_EQ(log.find("Uncaught"), std::string::npos) << log;        // script errors
  // Every picture the page shows is there (a broken image is no console error).
  for (auto at = dom.find("src=\""); at != std::string::npos; at = dom.find("src=\"", at + 1)) {
    const std::string src = dom.substr(at + 5, dom.find('"', at + 5) - at - 5);
    EXPECT_TRUE(fs::exists(dir_ / "out" / src)) << src;
  }

  // `report` rebuilds the same rows from the directories alone.
  fs::remove(dir_ / "out" / "summary.csv");
  const auto rep = test::run_cli("report " + (dir_ / "out").string(), dir_);
  EXPECT_EQ(rep.exit_code, 6) << rep.err;
  EXPECT_EQ(statuses(dir_ / "out" / "summary.csv"), expected);
}

TEST_F(CliBatch, HangingScanTimesOut) {
  write_scan(in_ / "line1" / "a.pcd", 1);
  // hang.pcd waits forever: killed after 30 s (60 s sanitized, on the small scans; 150 s on
  // full-size ones). The timeout leaves room for a.pcd, whose clock includes the worker's
  // start: 30 s were too few in the sanitizer build on a loaded machine.
  write_scan(in_ / "line1" / "hang.pcd", 2);
  const int slowdown = test::small_runs() ? std::min(test::kSlowdown, 2) : test::kSlowdown;
  const std::string timeout = std::to_string(30 * slowdown);
  const auto r = test::run_cli(batch("--jobs 1 --scan-timeout " + timeout + " --progress none"),
                               dir_, "GROOVETRACE_TEST_HANG_SCAN=hang.pcd");
  EXPECT_EQ(r.exit_code, 6) << r.err;
  EXPECT_EQ(r.err, "");
  const std::map<std::string, std::string> expected = {{"line1/a", "ok"},
                                                       {"line1/hang", "timeout"}};
  EXPECT_EQ(statuses(dir_ / "out" / "summary.csv"), expected);
}

// A kill -9 mid-batch loses at most the scans in flight; --resume redoes only those and the
// ones not started, and reruns everything when a parameter changes.
TEST_F(CliBatch, KilledBatchResumes) {
  for (unsigned k = 0; k < 6; ++k)
    write_scan(in_ / "line1" / ("s" + std::to_string(k) + ".pcd"), k + 1);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const std::string out = (dir_ / "out").string();
    ::execl(GT_CLI_PATH, GT_CLI_PATH, "batch", in_.c_str(), "-o", out.c_str(), "--backend", "cpu",
            "--jobs", "1", "--progress", "none", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(120 * test::kSlowdown);
  // Wait for two whole scan directories: a scan.json still under .partial is not done yet (it
  // was counted once, and the kill then came before its rename: CI saw one done scan of two).
  while (done_scans(dir_ / "out").size() < 2) {
    ASSERT_LT(std::chrono::steady_clock::now(), deadline) << "the batch made no progress";
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // its worker follows it

  const std::map<std::string, std::string> before = done_scans(dir_ / "out");
  ASSERT_GE(before.size(), 2u);
  ASSERT_LT(before.size(), 6u) << "the batch finished before the kill";

  const auto r = test::run_cli(batch("--jobs 1 --resume --progress lines"), dir_);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(static_cast<std::size_t>(std::count(r.err.begin(), r.err.end(), '\n')),
            6 - before.size())
      << r.err;
  for (const auto& [path, text] : before) EXPECT_EQ(test::read_text(path), text) << path;
  EXPECT_EQ(count_files(dir_ / "out", "scan.json"), 6u);
  EXPECT_EQ(count_files(dir_ / "out", "trajectory.csv"), 6u);
  EXPECT_EQ(count_files(dir_ / "out", ".tmp"), 0u);
  EXPECT_FALSE(fs::exists(dir_ / "out" / ".partial"));

  const auto again = test::run_cli(batch("--jobs 1 --resume --progress lines --step 0.003"), dir_);
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(std::count(again.err.begin(), again.err.end(), '\n'), 6) << again.err;
}

// A resumed batch keeps a scan without groove and still says that not every scan is ok.
TEST_F(CliBatch, KeptFailuresStillCount) {
  write_scan(in_ / "line1" / "a.pcd", 1);
  write_scan(in_ / "line1" / "flat.pcd", 2, 0.0);
  EXPECT_EQ(test::run_cli(batch("--progress none"), dir_).exit_code, 6);
  const auto again = test::run_cli(batch("--resume --progress lines"), dir_);
  EXPECT_EQ(again.exit_code, 6) << again.err;
  EXPECT_EQ(again.err, "");  // nothing run again
  EXPECT_NE(again.out.find("2 scans (shard 0/1): 1 ok, 1 not ok, 2 of them kept"),
            std::string::npos)
      << again.out;
}

TEST_F(CliBatch, BadUsageAndInputs) {
  write_scan(in_ / "line1" / "a.pcd", 1);
  EXPECT_EQ(test::run_cli(batch("--shard 2/2"), dir_).exit_code, 2);
  EXPECT_EQ(test::run_cli(batch("--shard x"), dir_).exit_code, 2);
  EXPECT_EQ(test::run_cli(batch("--progress loud"), dir_).exit_code, 2);
  EXPECT_EQ(test::run_cli(batch("--scan-timeout 0"), dir_).exit_code, 2);
  EXPECT_EQ(test::run_cli(batch("--radius 3"), dir_).exit_code, 2);
  const auto missing =
      test::run_cli("batch " + (dir_ / "nope").string() + " -o " + (dir_ / "out").string(), dir_);
  EXPECT_EQ(missing.exit_code, 3);
  EXPECT_NE(missing.err.find("does not exist"), std::string::npos) << missing.err;
  fs::create_directories(dir_ / "empty_dir");
  EXPECT_EQ(test::run_cli(
                "batch " + (dir_ / "empty_dir").string() + " -o " + (dir_ / "out").string(), dir_)
                .exit_code,
            3);
  EXPECT_EQ(test::run_cli("report " + (dir_ / "empty_dir").string(), dir_).exit_code, 3);
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "a refused batch writes nothing";
}

}  // namespace
}  // namespace groovetrace
