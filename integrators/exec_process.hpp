// A child process driven over its stdin/stdout pipes with a per-call time budget: what the `exec`
// method (integrators/exec_method.cpp, docs/PYTHON.md "Integrators in any language: exec:") uses to
// talk to a user's integrator. Started without a shell; every failure is a PipeError that names it.
#pragma once

#include <sys/types.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace geomint {

// What went wrong on the pipe: `reason` is the short status code of a failure row
// ("exec_died", "exec_timeout", "exec_malformed"), the message says what happened.
class PipeError : public std::runtime_error {
 public:
  PipeError(std::string reason, const std::string& message)
      : std::runtime_error(message), reason_(std::move(reason)) {}
  const std::string& reason() const { return reason_; }

 private:
  std::string reason_;
};

// "exited with status 3", "killed by signal 9 (Killed)": a waitpid() status in words.
std::string describe_wait_status(int status);

class ChildProcess {
 public:
  // Starts argv[0] (looked up in PATH when it has no '/') with its stdin and stdout on pipes,
  // stderr shared with ours, every other descriptor closed, SIGPIPE at its default. Throws
  // PipeError("exec_spawn", ...) when it cannot start (no such file, not executable).
  explicit ChildProcess(const std::vector<std::string>& argv);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // Writes all of `bytes` within `timeout_s` seconds; PipeError when the child is gone, does not
  // read, or the budget runs out (the child is then killed and reaped).
  void write_all(const std::string& bytes, double timeout_s, const std::string& what);
  // One line without its '\n' (at most `max_bytes`), within `timeout_s` seconds.
  std::string read_line(double timeout_s, const std::string& what, size_t max_bytes = 1 << 26);
  // Exactly `count` bytes, within `timeout_s` seconds.
  std::string read_bytes(size_t count, double timeout_s, const std::string& what);

  // Kills the child (SIGKILL) and reaps it; nothing when it has already ended.
  void kill_and_reap();
  bool running() const { return pid_ > 0; }
  pid_t pid() const { return pid_; }
  const std::string& program() const { return program_; }

 private:
  // Waits for the child to become readable/writable (`events`) until `deadline_ms` (monotonic).
  void wait_for(short events, double deadline_ms, const std::string& what, double timeout_s);
  // The pipe broke (`event`: "closed its output", "stopped reading its input"): reap the child
  // (killing it if it has not ended within 1 s) and throw PipeError("exec_died", ...) with its
  // exit status.
  [[noreturn]] void died(const std::string& what, const char* event);
  void fill_buffer(double deadline_ms, const std::string& what, double timeout_s);

  std::string program_;  // the command line, for messages
  pid_t pid_ = -1;
  int to_child_ = -1;    // our end of the child's stdin
  int from_child_ = -1;  // our end of the child's stdout
  std::string buffer_;   // bytes read but not yet returned
};

}  // namespace geomint
