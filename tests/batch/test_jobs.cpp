// The scans of a batch: folders, files and manifests expanded into jobs with directories that
// never collide, and the shards of a job array.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>

#include "batch/jobs.hpp"
#include "batch/row.hpp"
#include "support/cli_runner.hpp"

namespace groovetrace::batch {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> rels(const std::vector<ScanJob>& jobs) {
  std::vector<std::string> out;
  for (const ScanJob& j : jobs) out.push_back(j.rel);
  return out;
}

void touch(const fs::path& p) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << "x";
}

TEST(BatchJobs, FoldersAreSearchedSortedAndNamesNeverCollide) {
  const fs::path d = test::fresh_dir("batch_jobs_folders");
  touch(d / "in" / "b" / "scan.pcd");
  touch(d / "in" / "a" / "scan.pcd");
  touch(d / "in" / "a" / "scan.PLY");   // same stem, other extension
  touch(d / "in" / "a" / "notes.txt");  // not a scan
  touch(d / "in" / "a" / "s1.pcd");
  touch(d / "in" / "a" / "s1.labels.pcd");  // synth's ground truth beside s1.truth.json
  touch(d / "in" / "a" / "s1.truth.json");
  touch(d / "in" / "a" / "x.labels.pcd");  // no truth beside it: a scan
  touch(d / "other" / "a" / "s1.pcd");     // same relative path under a second input
  const auto jobs = list_jobs({(d / "in").string(), (d / "other").string()});
  EXPECT_EQ(rels(jobs), (std::vector<std::string>{"a/s1", "a/s1_2", "a/scan_pcd", "a/scan_ply",
                                                  "a/x.labels", "b/scan"}));
  EXPECT_EQ(jobs[1].path, (d / "other" / "a" / "s1.pcd").string());
  EXPECT_THROW(list_jobs({(d / "missing").string()}), InputError);
  touch(d / "loose" / "scan");  // a file named on the command line needs no extension
  EXPECT_EQ(rels(list_jobs({(d / "loose" / "scan").string()})), std::vector<std::string>{"scan"});
  fs::create_directories(d / "nothing");
  EXPECT_THROW(list_jobs({(d / "nothing").string()}), InputError);
}

TEST(BatchJobs, ManifestCarriesEachCapturesPose) {
  const fs::path d = test::fresh_dir("batch_jobs_manifest");
  std::ofstream(d / "night.csv") << "scan,flange_pose,viewpoint\n"
                                    "cell1/a.pcd,poses/a.yaml,\"0.1 0.2 0.3\"\n"
                                    "\n"
                                    "cell1/b.ply,,\n";
  const auto jobs = list_jobs({(d / "night.csv").string()});
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[0].rel, "cell1/a");
  EXPECT_EQ(jobs[0].path, (d / "cell1" / "a.pcd").string());
  EXPECT_EQ(jobs[0].flange_pose, (d / "poses" / "a.yaml").string());
  EXPECT_EQ(jobs[0].hand_eye, "");
  ASSERT_TRUE(jobs[0].viewpoint.has_value());
  EXPECT_FLOAT_EQ(jobs[0].viewpoint->z(), 0.3f);
  EXPECT_EQ(jobs[1].flange_pose, "");
  EXPECT_FALSE(jobs[1].viewpoint.has_value());

  std::ofstream(d / "no_scan.csv") << "file\na.pcd\n";
  EXPECT_THROW(read_manifest((d / "no_scan.csv").string()), InputError);
  std::ofstream(d / "ragged.csv") << "scan,flange_pose\na.pcd\n";
  EXPECT_THROW(read_manifest((d / "ragged.csv").string()), InputError);
  std::ofstream(d / "bad_view.csv") << "scan,viewpoint\na.pcd,1 2\n";
  EXPECT_THROW(read_manifest((d / "bad_view.csv").string()), InputError);
}

// Found by fuzz_manifest (docs/fuzzing.md). A job's directory is replaced whole by the batch:
// a row climbing out with ".." or naming an absolute path had one outside OUTDIR, and a counted
// name could be another row's own (a, a, a_2: two jobs in a_2), and "..pcd" had the directory
// "." (OUTDIR).
TEST(BatchJobs, ManifestDirectoriesStayInsideOutdirAndApart) {
  const fs::path d = test::fresh_dir("batch_jobs_manifest_dirs");
  std::ofstream(d / "m.csv") << "scan\n../x.pcd\n/data/cell/y.pcd\nsub/../../z.ply\n.\n"
                                "a.pcd\na.pcd\na_2.pcd\n..pcd\n";
  const auto jobs = list_jobs({(d / "m.csv").string()});
  EXPECT_EQ(rels(jobs), (std::vector<std::string>{"..pcd", "a", "a_2", "a_3", "data/cell/y", "scan",
                                                  "x", "z"}));
  EXPECT_EQ(jobs[4].path, "/data/cell/y.pcd");  // the file is still the row's
  EXPECT_EQ(jobs[6].path, (d / "../x.pcd").string());
  // The stem of "..pcd" is ".": OUTDIR itself, as a folder's file or one named alone too.
  touch(d / "in" / "..pcd");
  EXPECT_EQ(rels(list_jobs({(d / "in").string()})), std::vector<std::string>{"..pcd"});
  EXPECT_EQ(rels(list_jobs({(d / "in" / "..pcd").string()})), std::vector<std::string>{"..pcd"});
}

// A scan named after a file or folder the batch keeps in OUTDIR gets a counted name: its
// directory would have stood where summary.csv goes (the batch then failed at its end), or
// been the staging folder.
TEST(BatchJobs, ScansNamedLikeTheBatchsOwnFilesAreCounted) {
  const fs::path d = test::fresh_dir("batch_jobs_own_names");
  for (const char* name : {"summary.csv.pcd", "summary.json.ply", "index.html.pcd", ".partial.pcd"})
    touch(d / "in" / name);
  EXPECT_EQ(
      rels(list_jobs({(d / "in").string()})),
      (std::vector<std::string>{".partial_2", "index.html_2", "summary.csv_2", "summary.json_2"}));
}

// fuzz_manifest: the header of a CRLF file kept its "\r" in the message, two lines on a
// terminal.
TEST(BatchJobs, ManifestErrorsAreOneLine) {
  const fs::path d = test::fresh_dir("batch_jobs_manifest_crlf");
  std::ofstream(d / "m.csv", std::ios::binary) << "file\r\nx.pcd\r\n";
  try {
    read_manifest((d / "m.csv").string());
    ADD_FAILURE() << "a manifest without a scan column was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find_first_of("\r\n"), std::string::npos) << what;
    EXPECT_NE(what.find("got 'file?'"), std::string::npos) << what;
  }
}

TEST(BatchJobs, ShardsSplitTheSortedList) {
  std::vector<ScanJob> jobs(7);
  for (int i = 0; i < 7; ++i) jobs[i].rel = std::to_string(i);
  EXPECT_EQ(rels(shard(jobs, 0, 3)), (std::vector<std::string>{"0", "3", "6"}));
  EXPECT_EQ(rels(shard(jobs, 2, 3)), (std::vector<std::string>{"2", "5"}));
  int k = -1, n = -1;
  parse_shard("1/4", k, n);
  EXPECT_EQ(k, 1);
  EXPECT_EQ(n, 4);
  for (const char* bad : {"4/4", "-1/2", "1/0", "1", "a/b", "1/2x", ""}) {
    EXPECT_THROW(parse_shard(bad, k, n), UsageError) << bad;
  }
}

TEST(BatchJobs, ShardFromTheEnvironment) {
  ::unsetenv("JOB_COMPLETION_INDEX");
  ::setenv("SLURM_ARRAY_TASK_ID", "5", 1);
  ::setenv("SLURM_ARRAY_TASK_COUNT", "3", 1);
  ::setenv("SLURM_ARRAY_TASK_MIN", "4", 1);  // --array=4-6
  int k = -1, n = -1;
  EXPECT_TRUE(shard_from_environment(0, k, n));
  EXPECT_EQ(k, 1);
  EXPECT_EQ(n, 3);
  ::setenv("SLURM_ARRAY_TASK_ID", "x", 1);
  EXPECT_THROW(shard_from_environment(0, k, n), UsageError);
  ::unsetenv("SLURM_ARRAY_TASK_ID");
  ::unsetenv("SLURM_ARRAY_TASK_COUNT");
  ::unsetenv("SLURM_ARRAY_TASK_MIN");
  EXPECT_FALSE(shard_from_environment(0, k, n));
  ::setenv("JOB_COMPLETION_INDEX", "2", 1);
  EXPECT_THROW(shard_from_environment(0, k, n), UsageError);  // the count must be given
  EXPECT_TRUE(shard_from_environment(4, k, n));
  EXPECT_EQ(k, 2);
  EXPECT_EQ(n, 4);
  ::unsetenv("JOB_COMPLETION_INDEX");
}

TEST(BatchRows, JsonRoundTripAndCsvQuoting) {
  ScanRow r;
  r.scan = "a,b \"quoted\".pcd";
  r.dir = "a/b";
  r.status = "invalid_input";
  r.exit_code = 3;
  r.message = "line one, with a comma";
  r.stages_ms = {{"load", 1.5}, {"candidates", 20}};
  r.input_hash = hex64(fnv1a64("abc"));
  const ScanRow back = row_from_json(row_json(r), "test");
  EXPECT_EQ(back.scan, r.scan);
  EXPECT_EQ(back.stages_ms, r.stages_ms);
  EXPECT_EQ(back.input_hash, "e71fa2190541574b");  // FNV-1a 64 of "abc", a published test vector
  EXPECT_EQ(csv_line(r).substr(0, 25), "\"a,b \"\"quoted\"\".pcd\",a/b,");
  EXPECT_THROW(row_from_json("{}", "test"), InputError);
}

TEST(BatchJobs, DepthPngsCountWhereTheirIntrinsicsAreAndOutdirIsNeverSearched) {
  const fs::path d = test::fresh_dir("batch_jobs_png");
  touch(d / "in" / "a.png");
  touch(d / "in" / "a.json");     // a's intrinsics
  touch(d / "in" / "photo.png");  // none: not a scan
  touch(d / "in" / "cell" / "intrinsics.json");
  touch(d / "in" / "cell" / "b.png");
  touch(d / "in" / "old_run" / "report.json");  // a run's output folder inside the input
  touch(d / "in" / "old_run" / "overview.png");
  touch(d / "in" / "night" / "c" / "scan.json");  // the batch's own OUTDIR inside the input
  touch(d / "in" / "night" / "c" / "thumbnail.png");
  touch(d / "in" / "night" / "c" / "annotated.pcd");
  touch(d / "in" / "night" / "c" / "c.png");
  touch(d / "in" / "night" / "c" / "c.json");
  const std::string night = (d / "in" / "night").string();
  EXPECT_EQ(rels(list_jobs({(d / "in").string()}, {night, false})),
            (std::vector<std::string>{"a", "cell/b"}));
  EXPECT_EQ(rels(list_jobs({(d / "in").string()}, {night, true})),
            (std::vector<std::string>{"a", "cell/b", "photo"}));
  // Without knowing OUTDIR (an older caller), its scans are found as before.
  EXPECT_EQ(rels(list_jobs({(d / "in").string()})),
            (std::vector<std::string>{"a", "cell/b", "night/c/annotated", "night/c/c"}));
  fs::remove_all(d);
}

}  // namespace
}  // namespace groovetrace::batch
