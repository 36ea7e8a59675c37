// Integrators written in Python (docs/PYTHON.md "Python methods"): register_method puts a Python
// step(problem, q, p, t, h) -> (q, p) into the method registry with provider "user", so run, order,
// sweep and the verify kit drive it like a built-in; whatever it returns wrong is a failure row.
#include "python/python_method.hpp"

#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include "harness/run.hpp"
#include "integrators/integrator.hpp"
#include "python/interrupt_scope.hpp"
#include "python/py_problem.hpp"
#include "verify/verify.hpp"

namespace geomint {
namespace {

// One registration. Never freed: integrators of a run may still point at it when the same name is
// registered again, and its Python references must not be dropped without the GIL at exit.
struct PythonMethod {
  std::string summary;
  MethodInfo info;
  py::object step;     // the callable, when a function or an instance was registered
  py::object factory;  // a class: each integrator (one per run) makes its own instance
};

std::mutex& table_mutex() {
  static std::mutex mutex;
  return mutex;
}
// Read by integrator factories on harness threads without the GIL, hence the mutex.
std::map<std::string, const PythonMethod*>& python_methods() {
  static auto* methods = new std::map<std::string, const PythonMethod*>();
  return *methods;
}

const PythonMethod* find_python_method(const std::string& name) {
  std::lock_guard<std::mutex> lock(table_mutex());
  const auto found = python_methods().find(name);
  return found == python_methods().end() ? nullptr : found->second;
}

// The flags a Python step can honour: it sees ∇V, V and M only (no forces, constraints, first-order
// right-hand sides, Hessians or structures), so every Python method is also kConservativeOnly.
const std::vector<std::pair<std::string, MethodFlag>>& declarable_flags() {
  static const std::vector<std::pair<std::string, MethodFlag>> flags = {
      {"explicit", kExplicit},       {"implicit", kImplicit},
      {"symplectic", kSymplectic},   {"symmetric", kSymmetric},
      {"variational", kVariational}, {"energy_preserving", kEnergyPreserving},
  };
  return flags;
}

// "ZeroDivisionError: float division by zero (my_scheme.py:12)": the exception's type, message
// and the line that raised it, on one line (the row's message is one CSV cell).
std::string describe_exception(const py::error_already_set& error) {
  std::string text =
      fmt::format("{}: {}", py::str(error.type().attr("__name__")).cast<std::string>(),
                  py::str(error.value()).cast<std::string>());
  try {
    py::object trace = error.trace();
    if (!trace.is_none()) {
      while (!trace.attr("tb_next").is_none()) trace = trace.attr("tb_next");
      text += fmt::format(
          " ({}:{})",
          py::str(trace.attr("tb_frame").attr("f_code").attr("co_filename")).cast<std::string>(),
          trace.attr("tb_lineno").cast<int>());
    }
  } catch (const py::error_already_set&) {
    // No location: the message stands alone.
  }
  for (char& c : text) {
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

std::string type_name(const py::handle& object) {
  return py::str(py::type::handle_of(object).attr("__name__")).cast<std::string>();
}

class PythonIntegrator final : public Integrator {
 public:
  PythonIntegrator(std::string name, const PythonMethod* method)
      : name_(std::move(name)), method_(method) {}

  ~PythonIntegrator() override {
    if (view_.ptr() == nullptr && instance_.ptr() == nullptr && step_.ptr() == nullptr) return;
    if (!Py_IsInitialized()) return;  // interpreter gone: the references die with it
    py::gil_scoped_acquire gil;
    alive_.reset();
    view_ = py::object();
    step_ = py::object();
    instance_ = py::object();
  }

  MethodInfo info() const override { return method_->info; }

  // Python methods state no linear stability bound (a registry method must say why not).
  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none("a Python method declares no linear stability prediction");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    py::gil_scoped_acquire gil;
    setup_error_.clear();
    try {
      make_view(problem);
      if (!method_->factory.is_none()) {
        if (instance_.ptr() == nullptr) instance_ = method_->factory();
        step_ = instance_.attr("step");
      } else {
        step_ = method_->step;
      }
      // An optional reset(problem, q, p, t, h) prepares a method's own variables (a multistep
      // history); a plain function has none.
      if (instance_.ptr() != nullptr && py::hasattr(instance_, "reset")) {
        instance_.attr("reset")(view_, vector(state.q), vector(state.p), state.t, h);
        const PyProblem& view = view_.cast<const PyProblem&>();
        counters_.force_evals += view.gradient_calls;
        counters_.energy_evals += view.potential_calls;
      }
    } catch (const py::error_already_set& error) {
      setup_error_ = fmt::format("{}: {}", name_, describe_exception(error));
      if (error.matches(PyExc_KeyboardInterrupt)) request_interrupt();
    }
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    py::gil_scoped_acquire gil;
    if (!setup_error_.empty()) {
      return StepStatus::failure("python_exception", fmt::format("reset failed: {}", setup_error_));
    }
    if (step_.ptr() == nullptr) reset(problem, state, h);  // a caller that skipped reset()
    if (!setup_error_.empty()) {
      return StepStatus::failure("python_exception", fmt::format("reset failed: {}", setup_error_));
    }
    if (view_problem_ != &problem) make_view(problem);
    PyProblem& view = view_.cast<PyProblem&>();
    const long gradients = view.gradient_calls, potentials = view.potential_calls;
    py::object out;
    try {
      out = step_(view_, vector(state.q), vector(state.p), state.t, h);
    } catch (const py::error_already_set& error) {
      if (error.matches(PyExc_KeyboardInterrupt)) {
        request_interrupt();
        return StepStatus::failure(
            kInterruptedStatus,
            fmt::format("{}: KeyboardInterrupt in step() at t={:.6g}", name_, state.t));
      }
      return StepStatus::failure("python_exception",
                                 fmt::format("{}: step() raised {} at t={:.6g}", name_,
                                             describe_exception(error), state.t));
    }
    counters_.force_evals += view.gradient_calls - gradients;
    counters_.energy_evals += view.potential_calls - potentials;
    StepStatus status = read_state(out, state);
    if (status.ok) {
      state.t += h;  // the harness sets t_k exactly; this keeps a bare step() consistent
      ++counters_.steps;
    }
    return status;
  }

 private:
  static py::array_t<double> vector(const Vec& v) {
    py::array_t<double> array(v.size());
    std::copy(v.data(), v.data() + v.size(), array.mutable_data());
    return array;
  }

  void make_view(const Problem& problem) {
    if (!alive_) alive_ = std::make_shared<int>(0);
    view_ = py::cast(new PyProblem(problem, alive_), py::return_value_policy::take_ownership);
    view_problem_ = &problem;
  }

  StepStatus bad_return(const State& state, const std::string& what) const {
    return StepStatus::failure(
        "python_bad_return",
        fmt::format(
            "{}: step() must return (q, p), two float arrays of shape ({},); {} at t={:.6g}", name_,
            state.q.size(), what, state.t));
  }

  // Checks (q, p) as a whole before the state changes: a bad return names the first fault.
  StepStatus read_state(const py::object& out, State& state) const {
    if (!py::isinstance<py::tuple>(out) && !py::isinstance<py::list>(out)) {
      return bad_return(state, fmt::format("it returned a {}", type_name(out)));
    }
    const py::sequence pair = out;
    if (py::len(pair) != 2) {
      return bad_return(
          state, fmt::format("it returned a {} of length {}", type_name(out), py::len(pair)));
    }
    using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;
    const char* names[2] = {"q", "p"};
    Array arrays[2];
    for (int i = 0; i < 2; ++i) {
      arrays[i] = Array::ensure(pair[i]);
      if (!arrays[i]) {
        return bad_return(state, fmt::format("{} is a {}, not an array of numbers", names[i],
                                             type_name(pair[i])));
      }
      const Vec& expected = i == 0 ? state.q : state.p;
      if (arrays[i].ndim() != 1 || arrays[i].shape(0) != expected.size()) {
        std::vector<std::string> shape;
        for (py::ssize_t d = 0; d < arrays[i].ndim(); ++d) {
          shape.push_back(std::to_string(arrays[i].shape(d)));
        }
        return bad_return(state, fmt::format("{} has shape ({}{})", names[i],
                                             fmt::join(shape, ", "), shape.size() == 1 ? "," : ""));
      }
      for (py::ssize_t k = 0; k < arrays[i].shape(0); ++k) {
        if (!std::isfinite(arrays[i].at(k))) {
          return StepStatus::failure(
              "nan", fmt::format("{}: step() returned {}[{}] = {} at t={:.6g}", name_, names[i], k,
                                 arrays[i].at(k), state.t));
        }
      }
    }
    std::copy(arrays[0].data(), arrays[0].data() + state.q.size(), state.q.data());
    std::copy(arrays[1].data(), arrays[1].data() + state.p.size(), state.p.data());
    return StepStatus::success();
  }

  std::string name_;
  const PythonMethod* method_;
  std::shared_ptr<int> alive_;  // the views of this integrator's problem live while it does
  py::object view_;             // the problem as step() sees it
  const Problem* view_problem_ = nullptr;
  py::object instance_;  // a registered class's instance for this integrator
  py::object step_;      // the callable step() runs
  std::string setup_error_;
};

std::unique_ptr<Integrator> make_python_method(Params& params) {
  const std::string name = params.canonical();  // a Python method reads no parameters
  const PythonMethod* method = find_python_method(name);
  if (method == nullptr) {
    throw InputError(fmt::format("method '{}' is not a registered Python method", name));
  }
  return std::make_unique<PythonIntegrator>(name, method);
}

void register_python_method(const std::string& name, const py::object& step,
                            const py::object& factory, int order,
                            const std::vector<std::string>& flags, const std::string& summary,
                            const std::string& reference) {
  if (order < 1 || order > 20) {
    throw InputError(
        fmt::format("register_method: method '{}': order = {} (allowed: 1..20)", name, order));
  }
  unsigned bits = kConservativeOnly;
  for (const std::string& flag : flags) {
    bool known = false;
    for (const auto& [label, bit] : declarable_flags()) {
      if (label == flag) {
        bits |= bit;
        known = true;
      }
    }
    if (!known) {
      std::vector<std::string> allowed;
      for (const auto& [label, bit] : declarable_flags()) allowed.push_back(label);
      throw InputError(fmt::format(
          "register_method: method '{}': flag '{}' cannot be declared by a Python method "
          "(allowed: {})",
          name, flag, fmt::join(allowed, ", ")));
    }
  }
  if ((bits & kExplicit) && (bits & kImplicit)) {
    throw InputError(
        fmt::format("register_method: method '{}' declares both explicit and implicit", name));
  }
  if (!(bits & kImplicit)) bits |= kExplicit;
  auto* method = new PythonMethod{summary, MethodInfo{name, order, bits, reference}, step, factory};
  {
    std::lock_guard<std::mutex> lock(table_mutex());
    const auto found = python_methods().find(name);
    if (found != python_methods().end()) {
      found->second = method;  // registered again (a re-run notebook cell): the new definition
      return;
    }
  }
  // A built-in or C++ method of that name, or a bad name: register_method's InputError.
  register_method({name, summary, &make_python_method, {}});
  std::lock_guard<std::mutex> lock(table_mutex());
  python_methods()[name] = method;
}

py::dict check_row(const verify::CheckResult& result) {
  py::dict row;
  row["check"] = result.check;
  row["method"] = result.method;
  row["problem"] = result.problem;
  row["applies"] = result.applies;
  row["passed"] = result.passed;
  row["measured"] = result.measured;
  row["bound"] = result.bound;
  row["detail"] = result.detail;
  row["text"] = verify::describe(result);
  return row;
}

}  // namespace

std::string python_method_summary(const std::string& name, const std::string& registry_summary) {
  const PythonMethod* method = find_python_method(name);
  return method != nullptr ? method->summary : registry_summary;
}

void bind_python_methods(py::module_& module) {
  module.def("register_method", &register_python_method, py::arg("name"), py::arg("step"),
             py::arg("factory"), py::arg("order"), py::arg("flags"), py::arg("summary"),
             py::arg("reference"));
  module.def("python_methods", [] {
    std::vector<std::string> names;
    std::lock_guard<std::mutex> lock(table_mutex());
    for (const auto& [name, method] : python_methods()) names.push_back(name);
    return names;
  });
  module.def("check_names", &verify::check_names);
  module.def(
      "check",
      [](const std::string& method, const std::string& name, const std::string& constrained) {
        verify::CheckResult result;
        InterruptScope interrupt;
        {
          py::gil_scoped_release release;
          result = verify::run_check(method, name, constrained);
        }
        interrupt.raise_if_interrupted();
        return check_row(result);
      },
      py::arg("method"), py::arg("name"), py::arg("constrained_problem"));
}

}  // namespace geomint
