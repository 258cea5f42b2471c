#pragma once
// Typed errors: each carries the process exit code the CLI contract assigns to it.

#include <groovetrace/export.hpp>
#include <stdexcept>
#include <string>

namespace groovetrace {

/// Exit codes of the CLI (docs/design.md, "CLI contract"): 0 ok, 2 bad usage, 3 bad input, 4 no
/// groove, 5 internal, 6 (batch) a scan not ok, 7 a robot program failed its guards.
enum class ExitCode : int {
  kOk = 0,
  kUsage = 2,
  kInput = 3,
  kNoGroove = 4,
  kInternal = 5,
  kNotAllOk = 6,
  kUnsafe = 7
};

/// The status word of an exit code in report.json and batch summaries: ok, invalid_input,
/// no_groove, unsafe_program, or error (bad usage, internal).
inline const char* status_name(ExitCode code) {
  switch (code) {
    case ExitCode::kOk:
      return "ok";
    case ExitCode::kInput:
      return "invalid_input";
    case ExitCode::kNoGroove:
      return "no_groove";
    case ExitCode::kUnsafe:
      return "unsafe_program";
    default:
      return "error";
  }
}

/// Base of every error groovetrace throws on purpose; what() is one line, fit for stderr.
class GT_API Error : public std::runtime_error {
 public:
  Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ExitCode code() const { return code_; }

 private:
  ExitCode code_;
};

/// A flag, config value or argument is wrong (exit 2).
struct GT_API UsageError : Error {
  explicit UsageError(const std::string& m) : Error(ExitCode::kUsage, m) {}
};
/// A file cannot be read or holds no usable cloud; an output cannot be written (exit 3).
struct GT_API InputError : Error {
  explicit InputError(const std::string& m) : Error(ExitCode::kInput, m) {}
};
/// The scan was read but no groove was found in it (exit 4).
struct GT_API NoGrooveError : Error {
  explicit NoGrooveError(const std::string& m) : Error(ExitCode::kNoGroove, m) {}
};
/// A robot program would break a guard (robot/guards.hpp): a pose not finite, a jump, a fast
/// turn, the torch pointing out of the part, a pose outside the workspace (exit 7).
struct GT_API UnsafeProgramError : Error {
  explicit UnsafeProgramError(const std::string& m) : Error(ExitCode::kUnsafe, m) {}
};
/// A device or internal failure (exit 5).
struct GT_API InternalError : Error {
  explicit InternalError(const std::string& m) : Error(ExitCode::kInternal, m) {}
};

}  // namespace groovetrace
