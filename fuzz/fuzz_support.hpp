#pragma once
// What every harness shares: the input handed to the reader as a file, as a user's file is
// (the readers take paths, and the PLY reader opens its path twice), and the rule for what is
// a finding. A documented error (InputError, UsageError) with a one-line message is the right
// answer to a bad file; any other exception, a message of several lines (error.hpp promises
// one, fit for stderr), a broken promise of the reader's result, an abort, a sanitizer report
// or a timeout is a finding.

#include <stdlib.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <groovetrace/error.hpp>
#include <string>
#include <typeinfo>

namespace groovetrace::fuzz {

// Prints why the input is a finding and aborts, so libFuzzer saves it as a crash.
[[noreturn]] inline void finding(const std::string& why) {
  std::fprintf(stderr, "groovetrace fuzz finding: %s\n", why.c_str());
  std::fflush(stderr);
  std::abort();
}

inline void require(bool ok, const char* promise) {
  if (!ok) finding(std::string("broken promise: ") + promise);
}

// This process's own directory, under $GT_FUZZ_TMPDIR (scripts/fuzz.sh), else $TMPDIR or /tmp;
// removed when libFuzzer exits normally (a crash leaves it for scripts/fuzz.sh to clear).
inline const std::string& private_dir() {
  // Never destroyed: the exit handler below runs after static destructors would have.
  static const std::string& dir = *new std::string([] {
    const char* base = std::getenv("GT_FUZZ_TMPDIR");
    if (!base || !*base) base = std::getenv("TMPDIR");
    std::string tmpl = std::string(base && *base ? base : "/tmp") + "/groovetrace-fuzz-XXXXXX";
    if (!::mkdtemp(tmpl.data())) finding("cannot create a directory under " + tmpl);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(private_dir(), ec);
    });
    return tmpl;
  }());
  return dir;
}

// Writes the input to `name` in the private directory and returns its path.
inline std::string write_input(const std::string& name, const std::uint8_t* data,
                               std::size_t size) {
  const std::string path = private_dir() + "/" + name;
  // A new file each time: ext4 flushes a file truncated and rewritten when it is closed, and
  // that disk write was most of an input's time (300 instead of thousands per second).
  std::remove(path.c_str());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) finding("cannot write " + path);
  return path;
}

inline void require_one_line(const Error& e) {
  const std::string what = e.what();
  if (what.empty() || what.find_first_of("\n\r") != std::string::npos) {
    finding("an error message is not one line: \"" + what + "\"");
  }
}

// Runs `read`; the documented errors are answers, everything else escaping it is a finding.
template <typename Read>
void expect_answer(Read&& read) {
  try {
    read();
  } catch (const InputError& e) {
    require_one_line(e);
  } catch (const UsageError& e) {
    require_one_line(e);
  } catch (const std::exception& e) {
    finding(std::string("unexpected ") + typeid(e).name() + ": " + e.what());
  } catch (...) {
    finding("an exception that is no std::exception (an internal type escaped)");
  }
}

}  // namespace groovetrace::fuzz
