// Output files are complete or absent (docs/design.md, CLI contract): write a temporary file
// beside the target, make it durable, then rename it over the target, which POSIX makes atomic.

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <groovetrace/cloud_io.hpp>
#include <groovetrace/error.hpp>
#include <random>
#include <string>

namespace groovetrace {
namespace {

[[noreturn]] void fail(const std::string& path, int err) {
  // The message is one line even if the path holds control characters.
  std::string shown;
  for (char c : path) shown += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  throw InputError("cannot write " + shown + ": " + std::strerror(err));
}

std::string random_suffix() {
  // Seeded once per thread from the clock and the thread's address as well, so two
  // processes started in the same tick still diverge even if random_device is weak.
  thread_local std::mt19937_64 rng{
      std::random_device{}() ^
      static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
      reinterpret_cast<std::uintptr_t>(&rng) ^ static_cast<std::uint64_t>(::getpid())};
  static constexpr char kChars[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  std::string s(8, ' ');
  for (char& c : s) c = kChars[rng() % (sizeof(kChars) - 1)];
  return s;
}

// mkstemp would create the file 0600; opening with O_EXCL and mode 0666 lets the umask
// decide, so outputs get the same permissions as any other file the user creates.
int create_temp(const std::string& path, std::string& temp) {
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  // Keep the name under NAME_MAX (255) whatever the target's length.
  const std::string base = path.substr(slash == std::string::npos ? 0 : slash + 1, 200);
  for (int attempt = 0; attempt < 100; ++attempt) {
    temp = dir + "." + base + "." + random_suffix() + ".tmp";
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  return -1;  // errno is EEXIST
}

bool write_all(int fd, const std::string& bytes) {
  const char* p = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return true;
}

}  // namespace

void write_file_atomic(const std::string& path, const std::string& bytes) {
  if (path.empty() || path.back() == '/') fail(path, EISDIR);
  std::string temp;
  int fd = create_temp(path, temp);
  if (fd < 0) fail(path, errno);

  int err = 0;
  if (!write_all(fd, bytes)) err = errno;
  // Without fsync a crash after the rename can leave an empty file under the final name.
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && ::rename(temp.c_str(), path.c_str()) != 0) err = errno;
  if (err != 0) {
    ::unlink(temp.c_str());
    fail(path, err);
  }

  // Persist the rename itself; the file is already complete, so failure here is not fatal
  // (some file systems refuse fsync on directories).
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

}  // namespace groovetrace
