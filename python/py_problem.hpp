// The Problem object the Python package hands out (geomint.Problem): an owned problem parsed from
// a spec, or a view of the harness's problem that a Python method's step() receives, valid only
// while the run that passed it lasts (python/python_method.cpp).
#pragma once

#include <fmt/format.h>
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "harness/run_spec.hpp"
#include "problems/problem.hpp"
#include "problems/spec.hpp"

namespace geomint {

namespace py = pybind11;

// A ValueError, as an InputError would be, for a query the problem does not offer (the C++ API
// throws std::logic_error there, which would surface as a RuntimeError).
inline void require(const Problem& problem, Capability capability, const char* what) {
  if (!problem.has(capability)) {
    throw InputError(fmt::format("problem '{}' has no {}", problem.spec(), what));
  }
}

class PyProblem {
 public:
  explicit PyProblem(const std::string& spec) : problem_(parse_problem(spec)) {}
  // A view of `problem`, usable while `alive` has not expired (a Python method's run: the
  // harness owns the problem, and a step() that kept the object must not reach a freed one).
  PyProblem(const Problem& problem, const std::shared_ptr<void>& alive)
      : problem_(std::shared_ptr<void>(), &problem), alive_(alive), is_view_(true) {}

  const Problem& get() const {
    if (is_view_ && alive_.expired()) {
      throw InputError(
          "the problem passed to a Python method's step() is valid during its run only; keep a "
          "geomint.Problem(spec) to use it later");
    }
    return *problem_;
  }
  // The owned problem, shared with the runs started from it (a view is never run).
  const std::shared_ptr<const Problem>& shared() const {
    if (is_view_) get();
    return problem_;
  }

  py::tuple initial_state() const {
    const State state = get().initial_state();
    return py::make_tuple(state.q, state.p);
  }
  py::tuple exact(double t) const {
    require(get(), kExact, "exact solution");
    const State state = get().exact(t);
    return py::make_tuple(state.q, state.p);
  }
  Vec grad_potential(const Vec& q) const {
    require_separable("grad_potential");
    check_size(q, "q");
    Vec g;
    get().gradient(q, g);
    ++gradient_calls;
    return g;
  }
  double potential(const Vec& q) const {
    require_separable("potential");
    check_size(q, "q");
    ++potential_calls;
    return get().potential(q);
  }
  Vec mass() const {
    require_separable("mass");
    return get().mass();
  }
  Vec inverse_mass() const {
    require_separable("inverse_mass");
    return get().inverse_mass();
  }
  double energy(const Vec& q, const Vec& p) const {
    check_size(q, "q");
    if (!get().has(kFirstOrderOnly)) check_size(p, "p");
    return get().energy(q, p);
  }
  // The conserved quantities the problem declares, by the series columns' names.
  py::dict invariants(const Vec& q, const Vec& p) const {
    const Problem& problem = get();
    check_size(q, "q");
    if (!problem.has(kFirstOrderOnly)) check_size(p, "p");
    py::dict values;
    if (!problem.has(kFirstOrderOnly)) values["energy"] = problem.energy(q, p);
    if (problem.has(kLinearMomentum)) {
      values["linear_momentum"] = Vec(problem.linear_momentum(q, p));
    }
    if (problem.has(kAngularMomentum)) {
      values["angular_momentum"] = Vec(problem.angular_momentum(q, p));
    }
    if (problem.has(kCasimir)) values["casimir"] = problem.casimir(q, p);
    return values;
  }
  double period() const {
    require(get(), kPeriod, "period");
    return get().period();
  }

  // Evaluations asked for through this object: a Python method's work counters
  // (force_evals, energy_evals of its rows).
  mutable long gradient_calls = 0;
  mutable long potential_calls = 0;

 private:
  void require_separable(const char* what) const {
    if (get().kind() != ProblemKind::kSeparable) {
      throw InputError(
          fmt::format("problem '{}' is of kind {}: {} needs a separable problem (L = ½vᵀMv − V(q))",
                      get().spec(), kind_name(get().kind()), what));
    }
  }
  void check_size(const Vec& v, const char* name) const {
    if (v.size() != get().dof()) {
      throw InputError(fmt::format("{} has {} entries; problem '{}' has dof = {}", name, v.size(),
                                   get().spec(), get().dof()));
    }
  }
  std::shared_ptr<const Problem> problem_;
  std::weak_ptr<void> alive_;
  bool is_view_ = false;
};

}  // namespace geomint
