#include "batch/pool.hpp"

#include <poll.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <groovetrace/features.hpp>
#include <memory>
#include <string>

#include "batch/scan_dir.hpp"

namespace groovetrace::batch {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Worker {
  pid_t pid = -1;
  int to = -1, from = -1;  // our ends of its job pipe and its result pipe
  long job = -1;           // the job it runs, -1 when idle
  Clock::time_point start;
  std::string pending;  // result bytes not yet ending in a newline
};

std::string host_name() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof buf - 1) != 0) return "host";
  return buf;
}

// The worker's life: a backend set up once, then one job index per line until the pipe closes.
[[noreturn]] void worker_main(int in_fd, int out_fd, const std::vector<ScanJob>& jobs,
                              const Params& params, const std::string& out_dir) {
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a killed batch takes its workers along
  std::unique_ptr<FeatureBackend> backend;
  FILE* in = ::fdopen(in_fd, "r");
  char line[64];
  while (in && std::fgets(line, sizeof line, in)) {
    const std::size_t index = std::strtoul(line, nullptr, 10);
    std::string warned;
    try {
      if (!backend) backend = make_backend(params.backend, params.device);
      warned = backend->warning();
      run_scan(jobs.at(index), params, *backend, out_dir);
    } catch (const std::exception& e) {
      // The backend or OUTDIR itself failed: the scan's row says so.
      try {
        write_failure(
            failure_row(jobs.at(index), "error", static_cast<int>(ExitCode::kInternal), e.what()),
            out_dir);
      } catch (const std::exception&) {
        ::_exit(static_cast<int>(ExitCode::kInput));
      }
    }
    // A backend that fell back during this scan (auto: a cloud too large for the device) is set
    // up anew for the next one, which may fit; the kernels stay built.
    if (backend && backend->warning() != warned) backend.reset();
    const std::string done = std::to_string(index) + "\n";
    if (::write(out_fd, done.data(), done.size()) < 0) ::_exit(1);
  }
  ::_exit(0);
}

class Pool {
 public:
  Pool(const std::vector<ScanJob>& jobs, const Params& params, const std::string& out_dir,
       double timeout_s, const std::function<void(const ScanRow&)>& on_row)
      : jobs_(jobs), params_(params), out_dir_(out_dir), timeout_s_(timeout_s), on_row_(on_row) {
    for (std::size_t i = 0; i < jobs.size(); ++i) queue_.push_back(static_cast<long>(i));
  }
  ~Pool() {
    for (Worker& w : workers_) stop(w);
  }

  void run(int count) {
    workers_.resize(static_cast<std::size_t>(count));
    for (Worker& w : workers_) spawn(w);
    while (finished_ < jobs_.size()) {
      for (Worker& w : workers_) assign(w);
      wait_for_results();
      for (Worker& w : workers_) check_alive(w);
      for (Worker& w : workers_) check_timeout(w);
    }
  }

 private:
  void spawn(Worker& w) {
    int job_pipe[2], result_pipe[2];
    if (::pipe(job_pipe) != 0 || ::pipe(result_pipe) != 0) {
      throw InternalError(std::string("cannot create a worker's pipes: ") + std::strerror(errno));
    }
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) throw InternalError(std::string("cannot start a worker: ") + std::strerror(errno));
    if (pid == 0) {
      for (const Worker& other : workers_) {  // only its own pipes stay open in a worker
        if (other.to >= 0) ::close(other.to);
        if (other.from >= 0) ::close(other.from);
      }
      ::close(job_pipe[1]);
      ::close(result_pipe[0]);
      worker_main(job_pipe[0], result_pipe[1], jobs_, params_, out_dir_);
    }
    ::close(job_pipe[0]);
    ::close(result_pipe[1]);
    w = Worker{pid, job_pipe[1], result_pipe[0], -1, {}, ""};
  }

  void stop(Worker& w) {
    if (w.pid < 0) return;
    ::kill(w.pid, SIGKILL);
    ::waitpid(w.pid, nullptr, 0);
    close_pipes(w);
  }

  // Closed and forgotten: a later worker's child must not close a reused descriptor number.
  static void close_pipes(Worker& w) {
    ::close(w.to);
    ::close(w.from);
    w.to = w.from = -1;
    w.pid = -1;
  }

  void assign(Worker& w) {
    if (w.pid < 0 || w.job >= 0 || queue_.empty()) return;
    w.job = queue_.front();
    queue_.pop_front();
    w.start = Clock::now();
    const std::string line = std::to_string(w.job) + "\n";
    if (::write(w.to, line.data(), line.size()) < 0) {
      // The worker is gone; check_alive records its job.
    }
  }

  void wait_for_results() {
    std::vector<pollfd> fds;
    for (const Worker& w : workers_) fds.push_back({w.from, POLLIN, 0});
    if (::poll(fds.data(), fds.size(), 100) <= 0) return;
    for (std::size_t k = 0; k < fds.size(); ++k) {
      if (fds[k].revents & (POLLIN | POLLHUP)) drain(workers_[k], false);
    }
  }

  // Reads what the worker reported; `until_eof` after it died (its last words count).
  void drain(Worker& w, bool until_eof) {
    char buf[256];
    for (;;) {
      const ssize_t n = ::read(w.from, buf, sizeof buf);
      if (n <= 0) break;
      w.pending.append(buf, static_cast<std::size_t>(n));
      if (!until_eof) break;
    }
    std::size_t nl;
    while ((nl = w.pending.find('\n')) != std::string::npos) {
      const long index = std::strtol(w.pending.substr(0, nl).c_str(), nullptr, 10);
      w.pending.erase(0, nl + 1);
      if (index == w.job) finish(w, read_back(index));
    }
  }

  ScanRow read_back(long index) {
    ScanRow row;
    if (!read_row(out_dir_, jobs_[static_cast<std::size_t>(index)].rel, row)) {
      row = failure_row(jobs_[static_cast<std::size_t>(index)], "error",
                        static_cast<int>(ExitCode::kInternal),
                        "the worker reported the scan done but left no scan.json");
    }
    return row;
  }

  void finish(Worker& w, const ScanRow& row) {
    w.job = -1;
    ++finished_;
    on_row_(row);
  }

  // A worker that died: its finished scans count, the one it ran is recorded as crashed.
  void check_alive(Worker& w) {
    int status = 0;
    if (w.pid < 0 || ::waitpid(w.pid, &status, WNOHANG) != w.pid) return;
    drain(w, true);
    const long job = w.job;
    close_pipes(w);
    if (job >= 0) {
      const int sig = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
      const std::string why = sig ? "worker killed by signal " + std::to_string(sig) + " (" +
                                        strsignal(sig) + ") while running this scan"
                                  : "worker exited with code " +
                                        std::to_string(WEXITSTATUS(status)) + " during this scan";
      record(w, failure_row(jobs_[static_cast<std::size_t>(job)], "crashed",
                            sig ? 128 + sig : WEXITSTATUS(status), why));
    }
    if (finished_ < jobs_.size()) spawn(w);
  }

  void check_timeout(Worker& w) {
    if (w.pid < 0 || w.job < 0) return;
    const double s = std::chrono::duration<double>(Clock::now() - w.start).count();
    if (s <= timeout_s_) return;
    const long job = w.job;
    stop(w);
    char msg[128];
    std::snprintf(msg, sizeof msg, "killed after %.0f s (--scan-timeout)", timeout_s_);
    record(w, failure_row(jobs_[static_cast<std::size_t>(job)], "timeout",
                          static_cast<int>(ExitCode::kInternal), msg));
    if (finished_ < jobs_.size()) spawn(w);
  }

  void record(Worker& w, ScanRow row) {
    ScanRow previous;
    if (read_row(out_dir_, row.dir, previous)) row.input_hash = previous.input_hash;
    write_failure(row, out_dir_);
    finish(w, row);
  }

  const std::vector<ScanJob>& jobs_;
  const Params& params_;
  const std::string& out_dir_;
  double timeout_s_;
  const std::function<void(const ScanRow&)>& on_row_;
  std::deque<long> queue_;
  std::vector<Worker> workers_;
  std::size_t finished_ = 0;
};

}  // namespace

std::string partial_name(const std::string& rel) {
  return host_name() + "-" + std::to_string(::getpid()) + "-" + hex64(fnv1a64(rel));
}

namespace {

// A process that exists and has not exited. A killed batch's worker is reparented, and until
// its new parent reaps it, it is a zombie that kill(pid, 0) still finds: its .partial
// directory stayed, and a resume under load saw a scan twice (CliBatch.KilledBatchResumes).
bool still_running(pid_t pid) {
  if (::kill(pid, 0) != 0 && errno == ESRCH) return false;
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!stat || !std::getline(stat, text)) return true;  // no /proc: trust kill()
  const auto close = text.rfind(')');                   // the name in parentheses may hold spaces
  return close == std::string::npos || close + 2 >= text.size() || text[close + 2] != 'Z';
}

}  // namespace

void remove_stale_partials(const std::string& out_dir) {
  const fs::path partial = fs::path(out_dir) / ".partial";
  const std::string prefix = host_name() + "-";
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(partial, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const pid_t pid = static_cast<pid_t>(std::atol(name.c_str() + prefix.size()));
    if (pid > 0 && !still_running(pid)) fs::remove_all(entry.path(), ec);
  }
}

void run_in_workers(const std::vector<ScanJob>& jobs, const Params& params,
                    const std::string& out_dir, int workers, double timeout_s,
                    const std::function<void(const ScanRow&)>& on_row) {
  if (jobs.empty()) return;
  // A worker that dies between our write and its read must not kill the batch with SIGPIPE.
  const auto previous = std::signal(SIGPIPE, SIG_IGN);
  try {
    Pool pool(jobs, params, out_dir, timeout_s, on_row);
    pool.run(std::max(1, std::min<int>(workers, static_cast<int>(jobs.size()))));
  } catch (...) {
    std::signal(SIGPIPE, previous);
    throw;
  }
  std::signal(SIGPIPE, previous);
}

}  // namespace groovetrace::batch
