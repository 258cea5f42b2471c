// Why one swap and not one atomic rename per file: each file was complete, but a kill or a
// full disk between two renames left a new trajectory.csv beside an old program.script, and
// two runs into one folder ended with files of both. A cell controller that picks up
// program.script must find the program of the run whose report it reads.

#include "io/output_dir.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <memory>
#include <random>

#include "io/text.hpp"

namespace groovetrace::io {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail(const std::string& what, const fs::path& path, int err) {
  throw InputError("cannot " + what + " " + shown(path.string()) + ": " + std::strerror(err));
}

// An open directory, closed (and so unlocked) on destruction.
class OpenDir {
 public:
  explicit OpenDir(const fs::path& dir)
      : fd_(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC)) {}
  ~OpenDir() {
    if (fd_ >= 0) ::close(fd_);
  }
  OpenDir(const OpenDir&) = delete;
  OpenDir& operator=(const OpenDir&) = delete;
  bool ok() const { return fd_ >= 0; }
  bool lock(bool wait) { return ok() && ::flock(fd_, LOCK_EX | (wait ? 0 : LOCK_NB)) == 0; }
  void sync() {
    if (ok()) ::fsync(fd_);  // some file systems refuse; the renames happened regardless
  }

 private:
  int fd_;
};

// `-o out/`, `-o .` and a symlink to the real folder all name the folder itself.
fs::path resolved(const fs::path& target) {
  fs::path p = fs::absolute(target).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  std::error_code ec;
  const fs::path real = fs::weakly_canonical(p, ec);
  return ec ? p : real;
}

// Temporary names stay under NAME_MAX (255) whatever the target's length.
std::string temp_prefix(const fs::path& target) {
  return "." + target.filename().string().substr(0, 200) + ".groovetrace-";
}

void lock_folder(OpenDir& folder, const fs::path& path) {
  if (!folder.lock(true)) fail("lock", path, errno);
}

// What killed writers left beside `target`: temporaries whose flock nobody holds.
void remove_stale(const fs::path& target) {
  const std::string prefix = temp_prefix(target);
  std::vector<fs::path> stale;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(target.parent_path(), ec)) {
    if (e.path().filename().string().rfind(prefix, 0) != 0) continue;
    OpenDir d(e.path());
    if (!d.ok() || d.lock(false)) stale.push_back(e.path());
  }
  for (const auto& p : stale) fs::remove_all(p, ec);
}

// A new empty directory beside `target` with the permissions a mkdir gives (mkdtemp's are 0700).
fs::path make_temp(const fs::path& target) {
  static constexpr char kChars[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  std::random_device rd;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string name = temp_prefix(target);
    for (int k = 0; k < 6; ++k) name += kChars[rd() % (sizeof(kChars) - 1)];
    const fs::path p = target.parent_path() / name;
    if (::mkdir(p.c_str(), 0777) == 0) return p;
    if (errno != EEXIST) fail("create a directory beside", target, errno);
  }
  fail("create a directory beside", target, EEXIST);
}

std::string foreign_entry(const fs::path& dir, const NamePredicate& ours) {
  std::error_code ec;
  if (!fs::exists(fs::symlink_status(dir, ec))) return "";
  if (!fs::is_directory(dir, ec)) {
    throw InputError("output path " + shown(dir.string()) + " exists and is not a directory");
  }
  std::string first;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!ours(name) && (first.empty() || name < first)) first = name;
  }
  if (ec) fail("read", dir, ec.value());
  return first;
}

void require_ours(const fs::path& target, const NamePredicate& ours) {
  const std::string name = foreign_entry(target, ours);
  if (!name.empty()) {
    throw InputError("output directory " + shown(target.string()) + " holds " + shown(name) +
                     ", which groovetrace does not write: give a new or empty directory");
  }
}

// Moves `built` to `target`; returns where the target's old content now is ("" if none).
// The target keeps its permissions (a group-writable folder stays one).
fs::path swap_in(const fs::path& built, const fs::path& target) {
  struct stat old_mode {};
  if (::stat(target.c_str(), &old_mode) == 0) ::chmod(built.c_str(), old_mode.st_mode & 07777);
  if (::renameat2(AT_FDCWD, built.c_str(), AT_FDCWD, target.c_str(), RENAME_EXCHANGE) == 0) {
    return built;
  }
  fs::path old;
  if (errno == EINVAL || errno == ENOSYS) {  // the file system cannot exchange
    old = built.string() + "-old";
    if (::rename(target.c_str(), old.c_str()) != 0) fail("replace", target, errno);
  } else if (errno != ENOENT) {
    fail("replace", target, errno);
  }
  if (::rename(built.c_str(), target.c_str()) != 0) fail("write", target, errno);
  return old;
}

}  // namespace

void check_replaceable(const fs::path& target_in, const NamePredicate& ours) {
  const fs::path target = resolved(target_in);
  require_ours(target, ours);
  fs::path folder = target.parent_path();
  std::error_code ec;
  while (!fs::exists(folder, ec) && folder.has_relative_path()) folder = folder.parent_path();
  if (!fs::is_directory(folder, ec)) {
    throw InputError("cannot create output directory " + shown(target.string()) + ": " +
                     shown(folder.string()) + " is not a directory");
  }
  if (::access(folder.c_str(), W_OK) != 0) fail("write in", folder, errno);
}

void replace_directory(const fs::path& target_in,
                       const std::vector<std::pair<std::string, std::string>>& files,
                       const NamePredicate& ours) {
  const fs::path target = resolved(target_in);
  const fs::path folder = target.parent_path();
  if (target.filename().empty()) throw InputError("cannot replace the root directory");
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) fail("create", folder, ec.value());
  fs::path built;
  std::unique_ptr<OpenDir> held;  // our temporary's flock: another writer's clean-up skips it
  {
    OpenDir f(folder);
    lock_folder(f, folder);
    remove_stale(target);
    require_ours(target, ours);
    built = make_temp(target);
    held = std::make_unique<OpenDir>(built);
    if (!held->lock(false)) fail("lock", built, errno);
  }
  try {
    for (const auto& [name, bytes] : files) write_file_atomic((built / name).string(), bytes);
    OpenDir f(folder);
    lock_folder(f, folder);
    require_ours(target, ours);
    const fs::path old = swap_in(built, target);
    f.sync();
    if (!old.empty()) fs::remove_all(old, ec);
  } catch (...) {
    fs::remove_all(built, ec);
    throw;
  }
}

}  // namespace groovetrace::io
