// ChildProcess (exec_process.hpp): posix_spawnp with pipes, poll()-bounded reads and writes, and
// a kill-and-reap on every failure so that no child outlives its call or becomes a zombie.
#include "integrators/exec_process.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>

extern char** environ;

namespace geomint {
namespace {

double now_ms() {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<double>(now.tv_sec) * 1e3 + static_cast<double>(now.tv_nsec) * 1e-6;
}

void close_fd(int& fd) {
  if (fd >= 0) close(fd);
  fd = -1;
}

// write() with SIGPIPE blocked in this thread only, so that a child that has closed its stdin
// gives EPIPE here instead of killing the harness (or the Python interpreter that embeds it);
// a SIGPIPE left pending by the write is consumed before the mask is restored.
ssize_t write_without_sigpipe(int fd, const char* data, size_t size) {
  sigset_t pipe_only, old_mask;
  sigemptyset(&pipe_only);
  sigaddset(&pipe_only, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_only, &old_mask);
  const ssize_t written = write(fd, data, size);
  const int saved_errno = errno;
  if (written < 0 && saved_errno == EPIPE) {
    const timespec no_wait{0, 0};
    while (sigtimedwait(&pipe_only, nullptr, &no_wait) > 0) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  errno = saved_errno;
  return written;
}

}  // namespace

std::string describe_wait_status(int status) {
  if (WIFEXITED(status)) return fmt::format("exited with status {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    return fmt::format("killed by signal {} ({})", WTERMSIG(status), strsignal(WTERMSIG(status)));
  }
  return fmt::format("ended with wait status {}", status);
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv) {
  if (argv.empty()) throw PipeError("exec_spawn", "empty command");
  for (const auto& arg : argv) program_ += (program_.empty() ? "" : " ") + arg;
  int stdin_pipe[2], stdout_pipe[2];
  if (pipe2(stdin_pipe, O_CLOEXEC) != 0) {
    throw PipeError("exec_spawn", fmt::format("pipe: {}", strerror(errno)));
  }
  if (pipe2(stdout_pipe, O_CLOEXEC) != 0) {
    close(stdin_pipe[0]);
    close(stdin_pipe[1]);
    throw PipeError("exec_spawn", fmt::format("pipe: {}", strerror(errno)));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  // dup2 clears close-on-exec on 0 and 1; every other descriptor of ours (the pipe ends included)
  // is closed in the child, so it cannot hold another child's pipe open.
  posix_spawn_file_actions_adddup2(&actions, stdin_pipe[0], 0);
  posix_spawn_file_actions_adddup2(&actions, stdout_pipe[1], 1);
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t none, pipe_signal;
  sigemptyset(&none);
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  // The child starts with no signal blocked and SIGPIPE at its default, whatever we inherited.
  posix_spawnattr_setsigmask(&attributes, &none);
  posix_spawnattr_setsigdefault(&attributes, &pipe_signal);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  std::vector<char*> args;
  for (const auto& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
  args.push_back(nullptr);
  const int error = posix_spawnp(&pid_, args[0], &actions, &attributes, args.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attributes);
  close(stdin_pipe[0]);
  close(stdout_pipe[1]);
  if (error != 0) {
    pid_ = -1;
    close(stdin_pipe[1]);
    close(stdout_pipe[0]);
    throw PipeError("exec_spawn", fmt::format("cannot start '{}': {}", program_, strerror(error)));
  }
  to_child_ = stdin_pipe[1];
  from_child_ = stdout_pipe[0];
  fcntl(to_child_, F_SETFL, fcntl(to_child_, F_GETFL) | O_NONBLOCK);
  fcntl(from_child_, F_SETFL, fcntl(from_child_, F_GETFL) | O_NONBLOCK);
}

ChildProcess::~ChildProcess() {
  // Closing its stdin asks a well-behaved child to finish; one that has not within 100 ms is
  // killed. Either way it is reaped here.
  close_fd(to_child_);
  close_fd(from_child_);
  if (pid_ <= 0) return;
  for (int attempt = 0; attempt < 20; ++attempt) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      pid_ = -1;
      return;
    }
    usleep(5000);
  }
  kill_and_reap();
}

void ChildProcess::kill_and_reap() {
  close_fd(to_child_);
  close_fd(from_child_);
  if (pid_ <= 0) return;
  kill(pid_, SIGKILL);
  int status = 0;
  while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
  }
  pid_ = -1;
}

void ChildProcess::died(const std::string& what, const char* event) {
  close_fd(to_child_);
  close_fd(from_child_);
  std::string how = event;
  if (pid_ > 0) {
    // It closed stdout; give it a moment to end, then take whatever it did.
    int status = 0;
    pid_t reaped = 0;
    for (int attempt = 0; attempt < 200 && reaped == 0; ++attempt) {  // up to 1 s
      reaped = waitpid(pid_, &status, WNOHANG);
      if (reaped == 0) usleep(5000);
    }
    if (reaped == pid_) {
      how = describe_wait_status(status);
      pid_ = -1;
    } else {
      kill_and_reap();
      how = fmt::format("{} (killed)", event);
    }
  }
  throw PipeError("exec_died", fmt::format("process '{}' {} during {}", program_, how, what));
}

void ChildProcess::wait_for(short events, double deadline_ms, const std::string& what,
                            double timeout_s) {
  const int fd = events == POLLOUT ? to_child_ : from_child_;
  for (;;) {
    const double left = deadline_ms - now_ms();
    if (left <= 0) {
      const pid_t pid = pid_;
      kill_and_reap();
      throw PipeError("exec_timeout",
                      fmt::format("process '{}' did not answer {} within timeout={:g} s; killed "
                                  "pid {}",
                                  program_, what, timeout_s, pid));
    }
    pollfd entry{fd, events, 0};
    const int ready = poll(&entry, 1, static_cast<int>(std::ceil(left)));
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) throw PipeError("exec_died", fmt::format("poll: {}", strerror(errno)));
    if (ready == 0) continue;
    if (entry.revents & (events | POLLHUP | POLLERR)) return;
  }
}

void ChildProcess::write_all(const std::string& bytes, double timeout_s, const std::string& what) {
  if (to_child_ < 0) died(what, "had ended");
  const double deadline = now_ms() + timeout_s * 1e3;
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t written =
        write_without_sigpipe(to_child_, bytes.data() + done, bytes.size() - done);
    if (written > 0) {
      done += static_cast<size_t>(written);
      continue;
    }
    if (written < 0 && errno == EINTR) continue;
    if (written < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
      wait_for(POLLOUT, deadline, what, timeout_s);
      continue;
    }
    died(what, "stopped reading its input");  // EPIPE: it closed its stdin or ended
  }
}

void ChildProcess::fill_buffer(double deadline_ms, const std::string& what, double timeout_s) {
  if (from_child_ < 0) died(what, "had ended");
  for (;;) {
    char chunk[65536];
    const ssize_t got = read(from_child_, chunk, sizeof chunk);
    if (got > 0) {
      buffer_.append(chunk, static_cast<size_t>(got));
      return;
    }
    if (got == 0) died(what, "closed its output");
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) {
      wait_for(POLLIN, deadline_ms, what, timeout_s);
      continue;
    }
    died(what, "could not be read");
  }
}

std::string ChildProcess::read_line(double timeout_s, const std::string& what, size_t max_bytes) {
  const double deadline = now_ms() + timeout_s * 1e3;
  size_t searched = 0;
  for (;;) {
    const size_t newline = buffer_.find('\n', searched);
    if (newline != std::string::npos) {
      std::string line = buffer_.substr(0, newline);
      buffer_.erase(0, newline + 1);
      return line;
    }
    searched = buffer_.size();
    if (buffer_.size() > max_bytes) {
      kill_and_reap();
      throw PipeError("exec_malformed",
                      fmt::format("process '{}' wrote more than {} bytes without a newline "
                                  "during {}",
                                  program_, max_bytes, what));
    }
    fill_buffer(deadline, what, timeout_s);
  }
}

std::string ChildProcess::read_bytes(size_t count, double timeout_s, const std::string& what) {
  const double deadline = now_ms() + timeout_s * 1e3;
  while (buffer_.size() < count) fill_buffer(deadline, what, timeout_s);
  std::string bytes = buffer_.substr(0, count);
  buffer_.erase(0, count);
  return bytes;
}

}  // namespace geomint
