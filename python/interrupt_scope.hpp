// Ctrl-C during a harness call from Python: InterruptScope (docs/PYTHON.md "Ctrl-C").
#pragma once

#include <pybind11/pybind11.h>

#include <csignal>

#include "harness/run.hpp"

namespace geomint {

namespace py = pybind11;

inline void interrupt_on_signal(int) { request_interrupt(); }

// Ctrl-C during a harness call (docs/PYTHON.md "Ctrl-C"): while the GIL is released, Python's own
// SIGINT handler cannot run, so the outermost call in the main thread installs one that only sets
// the harness's interrupt flag (the run ends at its next step point) and restores Python's after;
// the call then raises KeyboardInterrupt. In other threads, or where SIGINT is ignored or left at
// its default, nothing is installed.
class InterruptScope {
 public:
  InterruptScope() {
    if (depth_++ > 0) return;
    clear_interrupt();
    const py::module_ threading = py::module_::import("threading");
    if (!threading.attr("current_thread")().is(threading.attr("main_thread")())) return;
    const py::module_ signal = py::module_::import("signal");
    const py::object handler = signal.attr("getsignal")(SIGINT);
    if (handler.is_none() || handler.equal(signal.attr("SIG_IGN")) ||
        handler.equal(signal.attr("SIG_DFL"))) {
      return;
    }
    struct sigaction ours {};
    ours.sa_handler = interrupt_on_signal;
    sigemptyset(&ours.sa_mask);
    installed_ = sigaction(SIGINT, &ours, &previous_) == 0;
  }
  ~InterruptScope() {
    if (--depth_ > 0) return;
    if (installed_) sigaction(SIGINT, &previous_, nullptr);
  }
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;

  // With the GIL held, after the call: KeyboardInterrupt when it was interrupted.
  void raise_if_interrupted() const {
    if (depth_ > 1 || !interrupt_requested()) return;
    clear_interrupt();
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    throw py::error_already_set();
  }

 private:
  static inline int depth_ = 0;  // only touched with the GIL held
  bool installed_ = false;
  struct sigaction previous_ {};
};

}  // namespace geomint
