// `run` writes OUTDIR as one set (docs/design.md, "CLI contract"): after a kill -9 at any
// moment, a full disk, a failed rerun or two runs at once, OUTDIR holds one run's files or
// none, never files of two runs, and no temporaries stay behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <groovetrace/cloud_io.hpp>
#include <map>
#include <optional>
#include <random>
#include <thread>

#include "support/cli_runner.hpp"
#include "support/scenes.hpp"

namespace groovetrace {
namespace {

namespace fs = std::filesystem;
using Set = std::map<std::string, std::string>;  // file name -> bytes

Set read_set(const fs::path& dir) {
  Set set;
  for (const auto& name : test::entries(dir)) set[name] = test::read_text(dir / name);
  return set;
}

// report.json differs run to run by its timings; every other file is byte-identical for the
// same input and parameters (CliRun.OutputsAreTheSameForEveryThreadCount).
bool same_run(const Set& a, const Set& b) {
  if (a.size() != b.size()) return false;
  for (const auto& [name, bytes] : a) {
    const auto it = b.find(name);
    if (it == b.end() || (name != "report.json" && it->second != bytes)) return false;
  }
  return true;
}

bool temporaries_beside(const fs::path& out) {
  for (const auto& name : test::entries(out.parent_path())) {
    if (name.find(".groovetrace-") != std::string::npos) return true;
  }
  return false;
}

class OutputSet : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir(::testing::UnitTest::GetInstance()->current_test_info()->name());
    out_ = dir_ / "out";
    test::VGrooveScene s = test::repeated_run_scene();  // both methods find its groove
    s.tilt_deg = 12;
    s.noise_sigma = 0.0002;
    scan_ = dir_ / "scan.pcd";
    write_file_atomic(scan_.string(), pcd_bytes(test::render_vgroove(s).cloud));
    test::identity_calibration(dir_);
  }
  // The flags of run A (robust), B (paper: every file differs from A's) and C (robust with
  // another waypoint step: the same time as A, so concurrent A and C write at once).
  static std::vector<std::string> flags(char which) {
    if (which == 'A') return {"--method", "robust"};
    if (which == 'B') return {"--method", "paper"};
    return {"--method", "robust", "--step", "0.003"};
  }
  std::vector<std::string> argv(char which) const {
    // Identity calibration files (written in SetUp): the set holds a program, and stderr only
    // what the tests look for.
    std::vector<std::string> args = {"run",
                                     scan_.string(),
                                     "-o",
                                     out_.string(),
                                     "-q",
                                     "--backend",
                                     "cpu",
                                     "--hand-eye",
                                     (dir_ / "hand_eye.yaml").string(),
                                     "--flange-pose",
                                     (dir_ / "flange.yaml").string()};
    for (const auto& f : flags(which)) args.push_back(f);
    return args;
  }
  std::string run_args(char which) const {
    std::string line;
    for (const auto& a : argv(which)) line += (line.empty() ? "" : " ") + a;
    return line;
  }
  test::CliResult run(char which, const std::string& env = "") {
    return test::run_cli(run_args(which), dir_, env);
  }
  // Starts `run` as a child process; returns its pid.
  pid_t start(char which) const {
    const std::vector<std::string> args = argv(which);
    std::vector<char*> c_args = {const_cast<char*>(GT_CLI_PATH)};
    for (const auto& a : args) c_args.push_back(const_cast<char*>(a.c_str()));
    c_args.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::execv(GT_CLI_PATH, c_args.data());
      ::_exit(127);
    }
    return pid;
  }
  // Both runs' sets, made once, to compare every later state of out_ with.
  void make_references(char a = 'A', char b = 'B') {
    for (char which : {a, b}) {
      const auto r = run(which);
      ASSERT_EQ(r.exit_code, 0) << r.err;
      (which == a ? set_a_ : set_b_) = read_set(out_);
    }
    ASSERT_FALSE(same_run(set_a_, set_b_));
  }
  // out_ holds one of the two reference sets whole, or nothing at all.
  void expect_one_set() const {
    if (!fs::exists(out_)) return;
    const Set now = read_set(out_);
    EXPECT_TRUE(same_run(now, set_a_) || same_run(now, set_b_)) << [&] {
      std::string names;
      for (const auto& [name, bytes] : now) names += " " + name;
      return "a mix:" + names;
    }();
  }
  fs::path dir_, out_, scan_;
  Set set_a_, set_b_;
};

// Files of an earlier run that this run does not write (program_2.script from --max-seams 3,
// a temporary of a per-file write) are gone with the set they belonged to.
TEST_F(OutputSet, ARerunLeavesOnlyItsOwnFiles) {
  fs::create_directories(out_);
  std::ofstream(out_ / "program_2.script") << "def weld_seam_2():\nend\n";
  std::ofstream(out_ / ".trajectory.csv.abcdEFGH.tmp") << "idx";
  const auto r = run('A');
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto report = nlohmann::json::parse(test::read_text(out_ / "report.json"));
  EXPECT_EQ(report["status"], "ok");
  std::vector<std::string> listed = {"report.json"};
  for (const auto& o : report["outputs"]) {
    listed.push_back(o["file"]);
    EXPECT_EQ(fs::file_size(out_ / listed.back()), o["bytes"].get<std::uintmax_t>());
  }
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(test::entries(out_), listed);
  EXPECT_FALSE(temporaries_beside(out_));
}

// The new set's directory takes the permissions the user gave the old one.
TEST_F(OutputSet, ARerunKeepsTheDirectorysPermissions) {
  ASSERT_EQ(run('A').exit_code, 0);
  fs::permissions(out_, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                            fs::perms::others_exec);
  const auto before = fs::status(out_).permissions();
  ASSERT_EQ(run('B').exit_code, 0);
  EXPECT_EQ(fs::status(out_).permissions(), before);
}

// A failed rerun replaces the earlier set by its report.json: no earlier program stays to be
// taken for this run's.
TEST_F(OutputSet, AFailedRerunLeavesOnlyItsReport) {
  ASSERT_EQ(run('A').exit_code, 0);
  ASSERT_TRUE(fs::exists(out_ / "program.script"));
  const auto r =
      test::run_cli("run " + (dir_ / "missing.pcd").string() + " -o " + out_.string(), dir_);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  test::expect_failure_report(out_, 3, r.err);
  const auto report = nlohmann::json::parse(test::read_text(out_ / "report.json"));
  EXPECT_EQ(report["input"], (dir_ / "missing.pcd").string());
}

// OUTDIR is replaced whole, so a directory holding anything else is refused before any work,
// and left as it was.
TEST_F(OutputSet, ADirectoryWithOtherFilesIsRefused) {
  fs::create_directories(out_);
  std::ofstream(out_ / "notes.txt") << "mine\n";
  std::ofstream(out_ / "program.script") << "old\n";
  const auto r = run('A');
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_EQ(r.err, "groovetrace: error: output directory " + out_.string() +
                       " holds notes.txt, which groovetrace does not write: give a new or empty "
                       "directory\n");
  EXPECT_EQ(test::entries(out_), (std::vector<std::string>{"notes.txt", "program.script"}));
  EXPECT_EQ(test::read_text(out_ / "program.script"), "old\n");
}

// A disk that fills while the set is written (here a file size limit: writes beyond it fail
// with EFBIG, as on a full disk with ENOSPC): the run fails with exit 3 and the earlier set
// gives way to the failure's report. With no room even for that, no earlier file stays.
TEST_F(OutputSet, AFullDiskLeavesTheReportOrNothing) {
  ASSERT_EQ(run('A').exit_code, 0);
  const std::string limited =
      "trap '' XFSZ; ulimit -f 64; exec " + std::string(GT_CLI_PATH) + " " + run_args('B');
  auto r = test::run_cli_command("sh -c \"" + limited + "\"", dir_);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
  test::expect_failure_report(out_, 3, r.err);

  ASSERT_EQ(run('A').exit_code, 0);
  const std::string none =
      "trap '' XFSZ; ulimit -f 0; exec " + std::string(GT_CLI_PATH) + " " + run_args('B');
  r = test::run_cli_command("sh -c \"" + none + "\"", dir_);
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_TRUE(test::entries(out_).empty());
  EXPECT_FALSE(temporaries_beside(out_));
}

// 24 runs killed with SIGKILL, alternating between two runs whose every file differs: half at a
// random moment of the run, half while the set is being written (a temporary beside out_
// exists). After each kill out_ holds one run's whole set; the next run clears the
// temporaries the kills left.
TEST_F(OutputSet, KillsAtRandomMomentsLeaveOneWholeSet) {
  make_references();
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_EQ(run('B').exit_code, 0);
  const auto full = std::chrono::steady_clock::now() - t0;
  std::mt19937 rng(7);
  int killed = 0, while_writing = 0;
  for (int k = 0; k < 24; ++k) {
    const pid_t pid = start(k % 2 ? 'B' : 'A');
    ASSERT_GT(pid, 0);
    if (k % 4 < 2) {
      std::this_thread::sleep_for(std::uniform_real_distribution<double>(0, 1)(rng) * full);
    } else {
      const auto deadline =
          std::chrono::steady_clock::now() + std::chrono::seconds(60 * test::kSlowdown);
      while (!temporaries_beside(out_) && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(rng() % 40));
      while_writing += temporaries_beside(out_);
    }
    ::kill(pid, SIGKILL);
    int status = 0;
    ::waitpid(pid, &status, 0);
    killed += WIFSIGNALED(status);
    SCOPED_TRACE("kill " + std::to_string(k));
    expect_one_set();
  }
  EXPECT_GE(killed, 20);
  EXPECT_GE(while_writing, 4);
  ASSERT_EQ(run('A').exit_code, 0);
  EXPECT_TRUE(same_run(read_set(out_), set_a_));
  EXPECT_FALSE(temporaries_beside(out_));
}

// What a reader that opened OUTDIR once finds there (the files read through that directory's
// descriptor), when report.json and every file it lists are there; else nothing (a set being
// removed after it was swapped out loses files one by one).
std::optional<Set> read_whole_set(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (fd < 0) return std::nullopt;
  const fs::path self = "/proc/self/fd/" + std::to_string(fd);  // this directory, whatever its name
  Set set;
  std::error_code ec;
  bool vanished = false;  // listed, then removed before it was opened
  for (const auto& e : fs::directory_iterator(self, ec)) {
    std::ifstream in(e.path(), std::ios::binary);  // once open, it reads whole even if removed
    vanished |= !in;
    std::stringstream bytes;
    bytes << in.rdbuf();
    set[e.path().filename().string()] = bytes.str();
  }
  ::close(fd);
  if (ec || vanished || !set.count("report.json")) return std::nullopt;
  const auto report = nlohmann::json::parse(set["report.json"], nullptr, false);
  if (report.is_discarded()) return std::nullopt;
  for (const auto& o : report["outputs"]) {
    if (!set.count(o["file"].get<std::string>())) return std::nullopt;
  }
  return set;
}

// Six runs into one OUTDIR at once, of two kinds that take the same time (so they write at
// the same moments), while a reader keeps reading OUTDIR: every whole set the reader finds is
// one run's, each run succeeds, and what stays is one run's whole set.
TEST_F(OutputSet, ConcurrentRunsNeverMix) {
  make_references('A', 'C');
  std::vector<pid_t> pids;
  for (char which : {'A', 'C', 'A', 'C', 'A', 'C'}) pids.push_back(start(which));
  std::atomic<bool> done{false};
  int seen = 0, mixed = 0;
  std::thread reader([&] {
    while (!done) {
      const auto set = read_whole_set(out_);
      if (!set) continue;
      ++seen;
      mixed += !same_run(*set, set_a_) && !same_run(*set, set_b_);
    }
  });
  for (pid_t pid : pids) {
    int status = 0;
    ::waitpid(pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  }
  done = true;
  reader.join();
  EXPECT_GE(seen, 1);
  EXPECT_EQ(mixed, 0) << "of " << seen << " sets read";
  ASSERT_TRUE(fs::exists(out_));
  expect_one_set();
  EXPECT_FALSE(temporaries_beside(out_));
}

}  // namespace
}  // namespace groovetrace
