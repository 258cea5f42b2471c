// `groovetrace send PROGRAM --robot HOST[:PORT]`: a URScript program to a Universal Robots
// controller's secondary interface (TCP 30002), which runs a `def NAME(): ... end` it receives
// as one text (docs/robot.md, "Sending a program to a UR controller"). The file is checked
// before any connection: a truncated or foreign file never reaches the robot.
#include <arpa/inet.h>
#include <fcntl.h>
#include <linux/sockios.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <groovetrace/error.hpp>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"

namespace groovetrace::cli {
namespace {

using Clock = std::chrono::steady_clock;

constexpr int kDefaultPort = 30002;                      // UR secondary interface
constexpr std::uint64_t kMaxProgramBytes = 64ull << 20;  // far beyond any weld program
constexpr double kDefaultTimeoutS = 5.0;

struct SendOptions {
  std::string program, robot;
  double timeout_s = kDefaultTimeoutS;
  bool quiet = false;
};

struct Endpoint {
  std::string host;
  std::string port;  // digits, 1-65535
};

// Text from the command line in a one-line message: control characters become '?'.
std::string shown(const std::string& text) {
  std::string out = text.substr(0, 300);
  for (char& c : out) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  return out;
}

// ---- HOST[:PORT] --------------------------------------------------------------------------

std::string port_or_throw(const std::string& text, const std::string& robot) {
  const bool digits = !text.empty() && text.size() <= 5 &&
                      text.find_first_not_of("0123456789") == std::string::npos;
  const long port = digits ? std::stol(text) : 0;
  if (port < 1 || port > 65535) {
    throw UsageError("send: --robot: port must be a number 1-65535, got '" + shown(text) +
                     "' in '" + shown(robot) + "'");
  }
  return std::to_string(port);
}

// "host", "host:port", "[v6]" or "[v6]:port". A bare IPv6 address (more than one ':') is
// ambiguous with a port and must be bracketed.
Endpoint parse_robot(const std::string& robot) {
  Endpoint e{robot, std::to_string(kDefaultPort)};
  std::string rest;
  if (!robot.empty() && robot.front() == '[') {
    const auto close = robot.find(']');
    if (close == std::string::npos)
      throw UsageError("send: --robot: no ']' in '" + shown(robot) + "'");
    e.host = robot.substr(1, close - 1);
    rest = robot.substr(close + 1);
    if (!rest.empty() && rest.front() != ':') {
      throw UsageError("send: --robot: expected ':PORT' after ']' in '" + shown(robot) + "'");
    }
  } else if (robot.find(':') != robot.rfind(':')) {
    throw UsageError("send: --robot: write an IPv6 address in brackets, [ADDR]:PORT, got '" +
                     shown(robot) + "'");
  } else if (const auto colon = robot.find(':'); colon != std::string::npos) {
    e.host = robot.substr(0, colon);
    rest = robot.substr(colon);
  }
  if (!rest.empty()) e.port = port_or_throw(rest.substr(1), robot);
  const bool bad_char = e.host.find_first_of(" \t\r\n/[]") != std::string::npos;
  if (e.host.empty() || bad_char) {
    throw UsageError("send: --robot: expected HOST[:PORT] with a host name or address, got '" +
                     shown(robot) + "'");
  }
  return e;
}

// ---- the program file -----------------------------------------------------------------------

[[noreturn]] void refuse(const std::string& path, const std::string& why) {
  throw InputError("send: " + shown(path) + ": " + why + "; nothing sent");
}

std::string read_program(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) refuse(path, std::strerror(errno));
  if (!S_ISREG(st.st_mode)) refuse(path, "not a regular file");
  if (static_cast<std::uint64_t>(st.st_size) > kMaxProgramBytes) {
    refuse(path, "larger than 64 MiB, not a program");
  }
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  if (!(in && ss << in.rdbuf()) && st.st_size > 0) refuse(path, "cannot be read");
  return ss.str();
}

// Byte offset of the first byte that breaks UTF-8 (or is NUL or another control character
// than tab, CR, LF), or npos.
std::size_t first_non_text(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f) return i;
      ++i;
      continue;
    }
    const int extra = (c & 0xe0) == 0xc0 ? 1 : (c & 0xf0) == 0xe0 ? 2 : (c & 0xf8) == 0xf0 ? 3 : -1;
    const bool bad_lead = extra < 0 || c == 0xc0 || c == 0xc1 || c > 0xf4;
    if (bad_lead || i + static_cast<std::size_t>(extra) >= s.size()) return i;
    for (int k = 1; k <= extra; ++k) {
      if ((static_cast<unsigned char>(s[i + k]) & 0xc0) != 0x80) return i;
    }
    i += static_cast<std::size_t>(extra) + 1;
  }
  return std::string::npos;
}

struct Line {
  int number;
  bool indented;        // starts with a blank or a tab
  std::string content;  // without indentation, trailing blanks and CR
};

std::vector<Line> lines_of(const std::string& text) {
  std::vector<Line> lines;
  std::size_t pos = 0;
  for (int n = 1; pos < text.size(); ++n) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(pos, end - pos);
    const auto first = line.find_first_not_of(" \t");
    const auto last = line.find_last_not_of(" \t\r");
    const std::string content =
        first == std::string::npos || last < first ? "" : line.substr(first, last - first + 1);
    lines.push_back({n, first != 0, content});
    pos = end + 1;
  }
  return lines;
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  }
  return true;
}

// NAME when `content` is "def NAME():" (blanks allowed before the parentheses), else "".
std::string def_name(const std::string& content) {
  if (content.rfind("def ", 0) != 0) return "";
  std::string rest = content.substr(4);
  const auto paren = rest.find('(');
  if (paren == std::string::npos) return "";
  std::string tail = rest.substr(paren);
  std::string name = rest.substr(0, paren);
  name.erase(0, name.find_first_not_of(' '));
  name.erase(name.find_last_not_of(' ') + 1);
  tail.erase(std::remove(tail.begin(), tail.end(), ' '), tail.end());
  return tail == "():" && is_identifier(name) ? name : "";
}

bool blank_or_comment(const Line& l) { return l.content.empty() || l.content[0] == '#'; }

// The program's name, after checking that the text is one complete top-level
// `def NAME():` ... `end`: only blank and comment lines outside it, every line of its body
// indented, closed by an unindented `end` (a file cut short has none).
std::string check_structure(const std::string& path, const std::string& text) {
  std::string name;
  bool closed = false;
  for (const Line& l : lines_of(text)) {
    const std::string where = "line " + std::to_string(l.number);
    if (blank_or_comment(l) || (l.indented && !name.empty() && !closed)) continue;
    if (l.indented) refuse(path, where + ": indented code outside the program's def");
    if (closed) refuse(path, where + ": code after the program's end (one def per program)");
    if (!name.empty()) {
      if (l.content != "end") refuse(path, where + ": unindented code inside def " + name);
      closed = true;
      continue;
    }
    name = def_name(l.content);
    if (name.empty()) refuse(path, where + ": expected 'def NAME():' at the top level");
  }
  if (name.empty()) refuse(path, "no 'def NAME():' program in the file");
  if (!closed) refuse(path, "def " + name + " has no matching 'end' (the file is cut short?)");
  return name;
}

// The program's name; throws InputError (exit 3) for anything but one complete program.
std::string check_program(const std::string& path, const std::string& text) {
  if (text.empty()) refuse(path, "empty file");
  const std::size_t bad = first_non_text(text);
  if (bad != std::string::npos) {
    refuse(path, "not UTF-8 text (byte " + std::to_string(bad) + ")");
  }
  const std::string name = check_structure(path, text);
  if (text.back() != '\n') refuse(path, "does not end with a newline (the file is cut short?)");
  return name;
}

// ---- the connection -------------------------------------------------------------------------

struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

std::string seconds(double s) {
  std::ostringstream out;
  out << s;
  return out.str();
}

int remaining_ms(Clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 1 << 30));
}

// Waits for `events` on fd until the deadline; false on timeout. EINTR waits again.
bool wait_for(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    pollfd p{fd, events, 0};
    const int r = ::poll(&p, 1, remaining_ms(deadline));
    if (r > 0) return true;
    if (r == 0) return false;
    if (errno != EINTR) return false;
  }
}

struct Target {
  Endpoint endpoint;
  std::string name() const {
    const bool v6 = endpoint.host.find(':') != std::string::npos;
    const std::string host = shown(endpoint.host);
    return (v6 ? "[" + host + "]" : host) + ":" + endpoint.port;
  }
};

[[noreturn]] void cannot(const Target& t, const std::string& why) {
  throw InputError("send: cannot reach " + t.name() + ": " + why + "; nothing sent");
}

// After the first byte: the program may have arrived in part (its `end` missing, the
// controller does not run it).
[[noreturn]] void cut_short(const Target& t, const std::string& why) {
  throw InputError("send: " + t.name() + ": " + why);
}

// Tries one address: a non-blocking connect with the deadline. Returns the socket or -1 with
// `why` set.
int try_connect(const addrinfo* a, Clock::time_point deadline, std::string& why) {
  Fd s{::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol)};
  if (s.fd < 0) {
    why = std::strerror(errno);
    return -1;
  }
  if (::connect(s.fd, a->ai_addr, a->ai_addrlen) != 0 && errno != EINPROGRESS) {
    why = std::strerror(errno);
    return -1;
  }
  if (!wait_for(s.fd, POLLOUT, deadline)) {
    why = "timed out";
    return -1;
  }
  int err = 0;
  socklen_t len = sizeof(err);
  ::getsockopt(s.fd, SOL_SOCKET, SO_ERROR, &err, &len);
  if (err != 0) {
    why = std::strerror(err);
    return -1;
  }
  const int fd = s.fd;
  s.fd = -1;
  return fd;
}

int connect_to(const Target& t, double timeout_s) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(t.endpoint.host.c_str(), t.endpoint.port.c_str(), &hints, &found);
  if (rc != 0) cannot(t, std::string("cannot resolve the host (") + ::gai_strerror(rc) + ")");
  std::unique_ptr<addrinfo, decltype(&::freeaddrinfo)> list(found, &::freeaddrinfo);
  const auto deadline =
      Clock::now() + std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  std::string why = "no address";
  for (const addrinfo* a = found; a; a = a->ai_next) {
    const int fd = try_connect(a, deadline, why);
    if (fd >= 0) return fd;
  }
  if (why == "timed out") why += " after " + seconds(timeout_s) + " s";
  cannot(t, why);
}

// Writes all of `text`: partial writes continue, EINTR retries, a full socket waits at most
// `timeout_s` for room. MSG_NOSIGNAL: a peer that closed gives EPIPE, not a SIGPIPE death.
void send_all(int fd, const std::string& text, const Target& t, double timeout_s) {
  const auto stall = std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::send(fd, text.data() + done, text.size() - done, MSG_NOSIGNAL);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
    } else if (n < 0 && errno == EINTR) {
      continue;
    } else if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      if (!wait_for(fd, POLLOUT, Clock::now() + stall)) {
        cut_short(t, "the controller took no data for " + seconds(timeout_s) + " s (" +
                         std::to_string(done) + " of " + std::to_string(text.size()) +
                         " bytes written)");
      }
    } else {
      cut_short(t, std::string("writing failed after ") + std::to_string(done) + " bytes (" +
                       std::strerror(errno) + ")");
    }
  }
}

// After the last byte: shut the socket down for writing and wait until the controller's TCP
// has acknowledged everything (SIOCOUTQ == 0), reading and dropping what it sends meanwhile
// (its state messages). Closing with unread data would send a reset that can cut the tail.
void finish(int fd, const Target& t, double timeout_s) {
  ::shutdown(fd, SHUT_WR);
  const auto deadline =
      Clock::now() + std::chrono::milliseconds(static_cast<long long>(timeout_s * 1000));
  char sink[4096];
  bool peer_done = false;  // the controller closed its side: nothing more to read
  for (;;) {
    int unacked = 0;
    if (::ioctl(fd, SIOCOUTQ, &unacked) != 0 || unacked == 0) break;
    if (Clock::now() >= deadline) {
      cut_short(t, "the controller did not acknowledge the last " + std::to_string(unacked) +
                       " bytes within " + seconds(timeout_s) + " s");
    }
    pollfd p{fd, static_cast<short>(peer_done ? 0 : POLLIN), 0};
    if (::poll(&p, 1, 10) > 0 && (p.revents & POLLIN)) {
      peer_done = ::recv(fd, sink, sizeof(sink), MSG_DONTWAIT) == 0;
    }
  }
  int err = 0;
  socklen_t len = sizeof(err);
  ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
  if (err != 0) cut_short(t, std::string("the connection failed (") + std::strerror(err) + ")");
}

int send_program(const SendOptions& o) {
  const Target target{parse_robot(o.robot)};
  if (!(std::isfinite(o.timeout_s) && o.timeout_s > 0 && o.timeout_s <= 3600)) {
    throw UsageError("send: --timeout must be a positive number of seconds up to 3600");
  }
  const std::string text = read_program(o.program);
  const std::string name = check_program(o.program, text);
  Fd s{connect_to(target, o.timeout_s)};
  send_all(s.fd, text, target, o.timeout_s);
  finish(s.fd, target, o.timeout_s);
  if (!o.quiet) {
    std::printf("groovetrace: sent program %s (%zu bytes, %s) to %s\n", name.c_str(), text.size(),
                shown(o.program).c_str(), target.name().c_str());
  }
  return 0;
}

}  // namespace

Command add_send_command(CLI::App& app) {
  auto o = std::make_shared<SendOptions>();
  CLI::App* sub = app.add_subcommand(
      "send", "send a URScript program to a UR controller's secondary interface (port 30002)");
  sub->add_option("program", o->program, "the URScript file (one def NAME(): ... end)")->required();
  sub->add_option("--robot", o->robot, "the controller: HOST[:PORT] (default port 30002)")
      ->required();
  sub->add_option("--timeout", o->timeout_s,
                  "seconds to connect, and at most without progress while sending (default 5)");
  sub->add_flag("-q,--quiet", o->quiet, "print nothing on success");
  return {sub, [o] { return send_program(*o); }};
}

}  // namespace groovetrace::cli
