// Boost.Odeint 1.74 wrappers: controlled dopri5 and rosenbrock4 (one accepted step per call),
// velocity Verlet and McLachlan's symplectic RKN SB3A (fixed step). Ahnert & Mulansky, AIP Conf.
// Proc. 1389 (2011); docs at boost.org/doc/libs/1_74_0/libs/numeric/odeint.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

// This file is compiled as C++17 (integrators/CMakeLists.txt): Boost 1.74's ublas, used by
// rosenbrock4, calls std::allocator::construct/destroy, which C++20 removed.
#include <boost/numeric/odeint/stepper/controlled_runge_kutta.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/rosenbrock4.hpp>
#include <boost/numeric/odeint/stepper/rosenbrock4_controller.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/symplectic_rkn_sb3a_mclachlan.hpp>
#include <boost/numeric/odeint/stepper/velocity_verlet.hpp>

#include "integrators/adaptive.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

namespace odeint = boost::numeric::odeint;
namespace ublas = boost::numeric::ublas;
using StdVector = std::vector<double>;

Eigen::Map<const Vec> view(const StdVector& v) {
  return {v.data(), static_cast<Eigen::Index>(v.size())};
}
Eigen::Map<Vec> view(StdVector& v) { return {v.data(), static_cast<Eigen::Index>(v.size())}; }
Eigen::Map<const Vec> view(const ublas::vector<double>& v) {
  return {&v.data()[0], static_cast<Eigen::Index>(v.size())};
}
Eigen::Map<Vec> view(ublas::vector<double>& v) {
  return {&v.data()[0], static_cast<Eigen::Index>(v.size())};
}

// ---------------------------------------------------------------------------------------------
// Controlled steppers: one accepted step per adaptive_step, retrying rejected attempts with the
// step the controller proposes. The stepper's own state (y, t, step size) is the state of record.
class OdeintAdaptive : public AdaptiveIntegrator {
 public:
  StepStatus adaptive_step(const Problem& problem, State& state, double t_stop) override {
    StepStatus status;
    if (!ready_to_step(problem, state, t_stop, status)) return status;
    // Tolerances below round-off: the controller would accept ever smaller steps near t = 0
    // until the step budget runs out; say so at once, as CVODE does.
    y_buffer_.resize(problem.first_order_size());
    problem.pack_first_order(state, y_buffer_.data());
    status = check_tolerances_above_roundoff(y_buffer_.data(), y_buffer_.size(),
                                             "too_much_accuracy", info().name);
    if (!status.ok) return status;
    // Odeint's own integrate functions give up after 500 failed attempts; so do we.
    constexpr int kMaxAttempts = 500;
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      // A step that would leave a sliver of less than 1% before t_stop is stretched to land on
      // it; a landing step ends exactly at t_stop (t + (t_stop − t) may round off it).
      const bool landing = t_ + 1.01 * dt_ >= t_stop;
      const double h = landing ? t_stop - t_ : dt_;
      if (!(h > 0) || t_ + h == t_) {
        return StepStatus::failure("odeint_step_underflow",
                                   fmt::format("step size {:g} underflows at t={:.17g}", h, t_));
      }
      double t = t_;
      double h_next = h;
      odeint::controlled_step_result result = odeint::fail;
      try {
        result = try_step(t, h_next);
      } catch (const std::exception& error) {
        return StepStatus::failure("odeint_exception", error.what());
      }
      if (result == odeint::fail) {
        ++counters_.rejected;
        dt_ = h_next;
        continue;
      }
      ++counters_.steps;
      // After a stretched landing step the controller's proposal reflects the short step; keep
      // the larger of it and the step size that was current before landing.
      t_ = landing ? t_stop : t;
      dt_ = landing ? std::max(dt_, h_next) : h_next;
      publish(state);
      state.t = t_;
      if (!state.q.allFinite() || !state.p.allFinite()) {
        return StepStatus::failure("nan", fmt::format("non-finite state at t={:.6g}", t_));
      }
      return StepStatus::success();
    }
    return StepStatus::failure(
        "odeint_too_many_rejections",
        fmt::format("{} rejected attempts in one step at t={:.6g}", kMaxAttempts, t_));
  }

 protected:
  explicit OdeintAdaptive(const AdaptiveSettings& settings)
      : AdaptiveIntegrator(settings, "odeint controlled steppers") {}

  // Base reset plus the starting step; derived resets load their state first.
  void begin(const Problem& problem, const State& state, double h) {
    begin_adaptive_reset(problem, state, h);
    y_buffer_.resize(problem.first_order_size());
    problem.pack_first_order(state, y_buffer_.data());
    try {
      problem.first_order_rhs(t_, y_buffer_, ydot_buffer_);
      ++counters_.force_evals;
      dt_ = starting_step(y_buffer_, ydot_buffer_, settings_.rtol, settings_.atol);
    } catch (const std::exception& error) {
      setup_status_ = StepStatus::failure("odeint_exception", error.what());
    }
  }

  // One attempt from (y, t_) with step h; on success t and y advance. h becomes the proposal.
  virtual odeint::controlled_step_result try_step(double& t, double& h) = 0;
  virtual void publish(State& state) const = 0;

  // y' = f(t, y), counted.
  void rhs(const Vec& y, Vec& ydot, double t) {
    ++counters_.force_evals;
    problem_->first_order_rhs(t, y, ydot);
  }

  double dt_ = 0.0;  // the controller's current step size
  Vec y_buffer_, ydot_buffer_;
};

// Dormand–Prince 5(4) with odeint's default error checker and step adjuster; FSAL derivative
// cached by the controlled stepper.
class OdeintDopri5 final : public OdeintAdaptive {
 public:
  using Stepper = odeint::runge_kutta_dopri5<StdVector>;
  using Controlled = odeint::controlled_runge_kutta<Stepper>;

  explicit OdeintDopri5(const AdaptiveSettings& settings) : OdeintAdaptive(settings) {}

  MethodInfo info() const override {
    // Sees only first_order_rhs: runs the general kind too (Hamilton's equations of its L).
    return {"odeint_dopri5", 5, kExplicit | kAdaptive | kFirstOrderCapable | kGeneralLagrangian,
            "Boost.Odeint runge_kutta_dopri5, controlled (Dormand & Prince 1980)"};
  }

  void reset(const Problem& problem, const State& state, double h) override {
    begin(problem, state, h);
    y_.resize(problem.first_order_size());
    problem.pack_first_order(state, view(y_).data());
    stepper_.emplace(odeint::make_controlled(settings_.atol, settings_.rtol, Stepper()));
  }

 private:
  odeint::controlled_step_result try_step(double& t, double& h) override {
    auto system = [this](const StdVector& y, StdVector& ydot, double time) {
      y_in_ = view(y);
      rhs(y_in_, ydot_out_, time);
      view(ydot) = ydot_out_;
    };
    return stepper_->try_step(system, y_, t, h);
  }

  void publish(State& state) const override {
    problem_->unpack_first_order(view(y_).data(), state);
  }

  StdVector y_;
  Vec y_in_, ydot_out_;
  std::optional<Controlled> stepper_;
};

// Shampine's 4th-order Rosenbrock method with its embedded 3rd-order error estimate; the
// Jacobian comes from the problem (a Hessian, or on a non-separable problem the analytic
// Jacobian of Hamilton's equations of its L, docs/MECHANICS_GENERAL.md §1). Each attempt factorises
// I/(γh) − J once and back-substitutes six times (rosenbrock4.hpp, do_step).
class OdeintRosenbrock4 final : public OdeintAdaptive {
 public:
  using Controller = odeint::rosenbrock4_controller<odeint::rosenbrock4<double>>;
  using UblasVector = ublas::vector<double>;
  using UblasMatrix = ublas::matrix<double>;

  explicit OdeintRosenbrock4(const AdaptiveSettings& settings) : OdeintAdaptive(settings) {}

  MethodInfo info() const override {
    return {"odeint_rosenbrock4", 4,
            kImplicit | kAdaptive | kNeedsHessian | kFirstOrderCapable | kGeneralLagrangian,
            "Boost.Odeint rosenbrock4, controlled (Shampine 1982; Hairer & Wanner II, §IV.7)"};
  }

  void reset(const Problem& problem, const State& state, double h) override {
    begin(problem, state, h);
    if (setup_status_.ok && !has_analytic_first_order_jacobian(problem)) {
      setup_status_ = StepStatus::failure(
          "needs_hessian", "odeint_rosenbrock4 needs the Jacobian, i.e. a problem Hessian");
    }
    y_.resize(problem.first_order_size());
    problem.pack_first_order(state, view(y_).data());
    controller_.emplace(settings_.atol, settings_.rtol);
  }

 private:
  odeint::controlled_step_result try_step(double& t, double& h) override {
    auto system = [this](const UblasVector& y, UblasVector& ydot, double time) {
      y_in_ = view(y);
      rhs(y_in_, ydot_out_, time);
      view(ydot) = ydot_out_;
    };
    auto jacobian = [this](const UblasVector& y, UblasMatrix& J, double time, UblasVector& dfdt) {
      y_in_ = view(y);
      problem_->first_order_jacobian(time, y_in_, jacobian_);
      ++counters_.hessian_evals;
      const auto n = static_cast<Eigen::Index>(y.size());
      J.resize(n, n, false);
      J.clear();
      for (int col = 0; col < jacobian_.outerSize(); ++col) {
        for (SparseMatrix::InnerIterator it(jacobian_, col); it; ++it)
          J(it.row(), col) += it.value();
      }
      // ∂f/∂t: zero unless a (possibly driven) force is present; then a central difference.
      auto time_derivative = view(dfdt);
      time_derivative.setZero();
      if (problem_->has(kForce)) {
        const double delta = 1e-7 * std::max(1.0, std::abs(time));
        Vec plus, minus;
        rhs(y_in_, plus, time + delta);
        rhs(y_in_, minus, time - delta);
        time_derivative = (plus - minus) / (2 * delta);
      }
    };
    counters_.linear_solves += 6;
    return controller_->try_step(std::make_pair(system, jacobian), y_, t, h);
  }

  void publish(State& state) const override {
    problem_->unpack_first_order(view(y_).data(), state);
  }

  UblasVector y_;
  Vec y_in_, ydot_out_;
  SparseMatrix jacobian_;
  std::optional<Controller> controller_;
};

// ---------------------------------------------------------------------------------------------
// Fixed-step symplectic steppers. Odeint's symplectic steppers assume a separable conservative
// system, so problems with a non-conservative force are refused rather than silently changed:
// by applicable() (flag kConservativeOnly), and by step() for a caller that bypasses it.

StepStatus refuse_force(const Problem& problem, const char* method) {
  if (!problem.has(kForce)) return StepStatus::success();
  return StepStatus::failure(
      "unsupported_force",
      fmt::format("{} integrates separable conservative systems only; problem '{}' has a "
                  "non-conservative force",
                  method, problem.name()));
}

// Velocity Verlet on (q, v) with a = M⁻¹(−∇V(q)); p = M v on output. Odeint keeps the
// acceleration at the current point between steps (one gradient per step); the stepper's (q, v)
// and acceleration are reused only while the incoming state is bitwise the one last returned,
// so a caller that edits the state gets a fresh start, never a stale acceleration.
class OdeintVelocityVerlet final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"odeint_velocity_verlet", 2, kExplicit | kSymplectic | kSymmetric | kConservativeOnly,
            "Boost.Odeint velocity_verlet (Swope et al. 1982; GNI §I.1.4)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // Störmer–Verlet (GNI §I.5)
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    cached_problem_ = nullptr;
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (StepStatus refused = refuse_force(problem, "odeint_velocity_verlet"); !refused.ok) {
      return refused;
    }
    const bool continuing = cached_problem_ == &problem && state.q.size() == last_q_.size() &&
                            state.q == last_q_ && state.p == last_p_;
    if (!continuing) {
      const int dof = problem.dof();
      qv_.first.resize(dof);
      qv_.second.resize(dof);
      view(qv_.first) = state.q;
      view(qv_.second) = MassOperator(problem).solve(state.q, state.p);
      stepper_.reset();  // recompute the acceleration at the new point
      cached_problem_ = &problem;
    }
    auto acceleration = [this, &problem](const StdVector& q, const StdVector&, StdVector& a,
                                         double) {
      eval_gradient(problem, view(q), gradient_);
      view(a) = -MassOperator(problem).constant_inverse_diagonal().cwiseProduct(gradient_);
    };
    try {
      stepper_.do_step(acceleration, qv_, state.t, h);
    } catch (const std::exception& error) {
      cached_problem_ = nullptr;
      return StepStatus::failure("odeint_exception", error.what());
    }
    state.q = view(qv_.first);
    state.p = MassOperator(problem).apply(state.q, view(qv_.second));
    state.t += h;
    last_q_ = state.q;
    last_p_ = state.p;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  odeint::velocity_verlet<StdVector> stepper_;
  std::pair<StdVector, StdVector> qv_;  // (q, v)
  const Problem* cached_problem_ = nullptr;
  Vec last_q_, last_p_, gradient_;
};

// McLachlan's symmetric 6-stage, 4th-order splitting (SB3A) on the canonical pair (q, p):
// q' = M⁻¹p, p' = −∇V(q). The stepper holds no state between steps.
class OdeintMcLachlan4 final : public Integrator {
 public:
  MethodInfo info() const override {
    return {"odeint_mclachlan4", 4, kExplicit | kSymplectic | kSymmetric | kConservativeOnly,
            "Boost.Odeint symplectic_rkn_sb3a_mclachlan (McLachlan, SIAM J. Sci. Comput. 16, "
            "1995)"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "no formula in geomint: the limit of the 6-stage SB3A splitting is not derived here");
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (StepStatus refused = refuse_force(problem, "odeint_mclachlan4"); !refused.ok) {
      return refused;
    }
    const int dof = problem.dof();
    qp_.first.resize(dof);
    qp_.second.resize(dof);
    view(qp_.first) = state.q;
    view(qp_.second) = state.p;
    auto velocity = [&problem](const StdVector& p, StdVector& dqdt) {
      view(dqdt) = MassOperator(problem).constant_inverse_diagonal().cwiseProduct(view(p));
    };
    auto force = [this, &problem](const StdVector& q, StdVector& dpdt) {
      eval_gradient(problem, view(q), gradient_);
      view(dpdt) = -gradient_;
    };
    try {
      stepper_.do_step(std::make_pair(velocity, force), qp_, state.t, h);
    } catch (const std::exception& error) {
      return StepStatus::failure("odeint_exception", error.what());
    }
    state.q = view(qp_.first);
    state.p = view(qp_.second);
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  odeint::symplectic_rkn_sb3a_mclachlan<StdVector> stepper_;
  std::pair<StdVector, StdVector> qp_;
  Vec gradient_;
};

AdaptiveSettings read_odeint_settings(Params& params) {
  return read_adaptive_settings(
      params,
      "maximum number of accepted steps over the whole run (the run then fails with status "
      "max_steps)");
}

}  // namespace

std::unique_ptr<Integrator> make_odeint_dopri5(Params& params) {
  return std::make_unique<OdeintDopri5>(read_odeint_settings(params));
}
std::unique_ptr<Integrator> make_odeint_rosenbrock4(Params& params) {
  return std::make_unique<OdeintRosenbrock4>(read_odeint_settings(params));
}
std::unique_ptr<Integrator> make_odeint_velocity_verlet(Params&) {
  return std::make_unique<OdeintVelocityVerlet>();
}
std::unique_ptr<Integrator> make_odeint_mclachlan4(Params&) {
  return std::make_unique<OdeintMcLachlan4>();
}

}  // namespace geomint
