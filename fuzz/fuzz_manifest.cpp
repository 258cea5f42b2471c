// Batch manifests (`batch night.csv`) through list_jobs, as the batch expands its inputs. Every
// job's directory is where the batch writes, replacing what is there: it must lie inside OUTDIR
// (relative, no "..") and be the job's own (jobs.hpp: no two jobs share one).

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <set>

#include "batch/jobs.hpp"
#include "fuzz_support.hpp"

namespace {

void check_jobs(const std::vector<groovetrace::batch::ScanJob>& jobs) {
  std::set<std::string> dirs;
  for (const auto& job : jobs) {
    const std::filesystem::path rel(job.rel);
    bool climbs = false;
    for (const auto& part : rel) climbs = climbs || part == "..";
    if (job.rel.empty() || job.rel == "." || rel.is_absolute() || climbs) {
      groovetrace::fuzz::finding("a job's directory \"" + job.rel + "\" is outside OUTDIR");
    }
    if (!dirs.insert(job.rel).second) {
      groovetrace::fuzz::finding("two jobs share the directory \"" + job.rel + "\"");
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = groovetrace::fuzz::write_input("night.csv", data, size);
  groovetrace::fuzz::expect_answer([&] { check_jobs(groovetrace::batch::list_jobs({path})); });
  return 0;
}
