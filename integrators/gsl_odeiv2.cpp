// GSL 2.7 odeiv2 wrappers: rk8pd, msbdf and rk4imp driven by gsl_odeiv2_evolve_apply, one
// accepted step per adaptive_step (GSL reference manual, "Ordinary Differential Equations",
// https://www.gnu.org/software/gsl/doc/html/ode-initval.html).
#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "integrators/adaptive.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

namespace geomint {
namespace {

struct DriverDeleter {
  void operator()(gsl_odeiv2_driver* driver) const { gsl_odeiv2_driver_free(driver); }
};
using DriverPtr = std::unique_ptr<gsl_odeiv2_driver, DriverDeleter>;

// GSL's default error handler aborts the process; inside a wrapper call its errors must become
// status codes instead. The previous handler is restored on exit (the handler is global).
class ScopedGslErrorsAsStatus {
 public:
  ScopedGslErrorsAsStatus() : previous_(gsl_set_error_handler_off()) {}
  ~ScopedGslErrorsAsStatus() { gsl_set_error_handler(previous_); }
  ScopedGslErrorsAsStatus(const ScopedGslErrorsAsStatus&) = delete;
  ScopedGslErrorsAsStatus& operator=(const ScopedGslErrorsAsStatus&) = delete;

 private:
  gsl_error_handler_t* previous_;
};

enum class GslMethod { kRk8pd, kMsbdf, kRk4imp };

class GslOdeiv2 final : public AdaptiveIntegrator {
 public:
  GslOdeiv2(GslMethod method, const AdaptiveSettings& settings)
      : AdaptiveIntegrator(settings, "GSL odeiv2 wrappers"), method_(method) {}

  MethodInfo info() const override {
    switch (method_) {
      case GslMethod::kRk8pd:
        // Sees only first_order_rhs: runs the general kind too (Hamilton's equations of its L).
        return {"gsl_rk8pd", 8, kExplicit | kAdaptive | kFirstOrderCapable | kGeneralLagrangian,
                "GSL odeiv2 rk8pd: embedded Runge-Kutta Prince-Dormand (8, 9)"};
      // msbdf and rk4imp take the Jacobian of first_order_rhs, which a non-separable problem
      // gives analytically (Hamilton's equations of its L, docs/MECHANICS_GENERAL.md §1).
      case GslMethod::kMsbdf:
        // Variable order 1..5: the declared order is the maximum.
        return {"gsl_msbdf", 5,
                kImplicit | kAdaptive | kNeedsHessian | kFirstOrderCapable | kGeneralLagrangian,
                "GSL odeiv2 msbdf: variable-order BDF in Nordsieck form (Byrne & Hindmarsh)"};
      case GslMethod::kRk4imp:
        return {"gsl_rk4imp", 4,
                kImplicit | kAdaptive | kNeedsHessian | kFirstOrderCapable | kGeneralLagrangian,
                "GSL odeiv2 rk4imp: 2-stage Gauss-Legendre implicit Runge-Kutta, step doubling"};
    }
    return {};
  }

  void reset(const Problem& problem, const State& state, double h) override {
    driver_.reset();
    begin_adaptive_reset(problem, state, h);
    y_.resize(problem.first_order_size());
    ydot_start_.resize(y_.size());
    problem.pack_first_order(state, y_.data());
    const bool needs_jacobian = method_ != GslMethod::kRk8pd;
    if (needs_jacobian && !has_analytic_first_order_jacobian(problem)) {
      setup_status_ = StepStatus::failure(
          "needs_hessian",
          fmt::format("{} needs the Jacobian, i.e. a problem Hessian", info().name));
      return;
    }
    system_ = {&function, needs_jacobian ? &jacobian : nullptr, y_.size(), this};

    if (function(t_, y_.data(), ydot_start_.data(), this) != GSL_SUCCESS) {
      setup_status_ = StepStatus::failure("gsl_status_badfunc",
                                          "f(t0, y0) is not finite or threw " + callback_error_);
      return;
    }
    h_ = starting_step(y_buffer_, ydot_buffer_, settings_.rtol, settings_.atol);

    const gsl_odeiv2_step_type* type = method_ == GslMethod::kRk8pd   ? gsl_odeiv2_step_rk8pd
                                       : method_ == GslMethod::kMsbdf ? gsl_odeiv2_step_msbdf
                                                                      : gsl_odeiv2_step_rk4imp;
    // The driver owns step, control (standard y-control from atol/rtol) and evolve and wires
    // them together; msbdf reads its error levels through it. Stepping itself is done with
    // gsl_odeiv2_evolve_apply, which takes a single step (gsl_odeiv2_driver_apply would
    // integrate to t1 in many).
    const ScopedGslErrorsAsStatus errors_as_status;
    driver_.reset(
        gsl_odeiv2_driver_alloc_y_new(&system_, type, h_, settings_.atol, settings_.rtol));
    if (!driver_) {
      setup_status_ =
          StepStatus::failure("gsl_status_alloc", "gsl_odeiv2_driver_alloc_y_new failed");
    }
  }

  StepStatus adaptive_step(const Problem& problem, State& state, double t_stop) override {
    StepStatus guard;
    if (!ready_to_step(problem, state, t_stop, guard)) return guard;
    // Tolerances below round-off: GSL would accept ever smaller steps near t = 0 until the
    // step budget runs out; say so at once, as CVODE does.
    guard = check_tolerances_above_roundoff(y_.data(), static_cast<long>(y_.size()),
                                            "too_much_accuracy", info().name);
    if (!guard.ok) return guard;
    // evolve_apply lands exactly on t1 only when the proposed step exceeds t1 − t (it then
    // stamps t = t1). A suggested step that would leave a sliver of less than 1% is stretched
    // to cover it, so the run ends on t_stop without a tiny last step.
    const double remaining = t_stop - t_;
    const bool landing = t_ + 1.01 * h_ >= t_stop;
    double h = landing ? 2 * remaining : h_;
    double t = t_;
    const unsigned long failed_before = driver_->e->failed_steps;
    int status = GSL_SUCCESS;
    {
      const ScopedGslErrorsAsStatus errors_as_status;
      status = gsl_odeiv2_evolve_apply(driver_->e, driver_->c, driver_->s, &system_, &t, t_stop, &h,
                                       y_.data());
    }
    counters_.rejected += static_cast<long>(driver_->e->failed_steps - failed_before);
    if (status != GSL_SUCCESS) {
      std::string message = fmt::format("gsl_odeiv2_evolve_apply at t={:.6g}: {} (status {})", t_,
                                        gsl_strerror(status), status);
      if (!callback_error_.empty()) message += "; callback error: " + callback_error_;
      return StepStatus::failure(fmt::format("gsl_status_{}", status), message);
    }
    ++counters_.steps;
    // GSL leaves h untouched after the step that reaches t1; otherwise h is the next suggestion.
    if (t != t_stop) h_ = h;
    t_ = t;
    problem.unpack_first_order(y_.data(), state);
    state.t = t_;
    return StepStatus::success();
  }

 private:
  // A non-finite derivative is a soft failure (GSL halves the step and retries); an exception is
  // GSL_EBADFUNC, which ends the step at once.
  static int function(double t, const double y[], double dydt[], void* self) {
    auto& gsl = *static_cast<GslOdeiv2*>(self);
    try {
      const auto n = static_cast<Eigen::Index>(gsl.y_.size());
      gsl.y_buffer_ = Eigen::Map<const Vec>(y, n);
      gsl.problem_->first_order_rhs(t, gsl.y_buffer_, gsl.ydot_buffer_);
      ++gsl.counters_.force_evals;
      if (!gsl.ydot_buffer_.allFinite()) return GSL_ERANGE;
      Eigen::Map<Vec>(dydt, n) = gsl.ydot_buffer_;
      return GSL_SUCCESS;
    } catch (const std::exception& error) {
      gsl.callback_error_ = error.what();
      return GSL_EBADFUNC;
    }
  }

  // dfdy is row-major: dfdy[i·n + j] = ∂f_i/∂y_j. ∂f/∂t is zero unless a (possibly driven)
  // force is present; then it is a central difference in t of the right-hand side.
  static int jacobian(double t, const double y[], double* dfdy, double dfdt[], void* self) {
    auto& gsl = *static_cast<GslOdeiv2*>(self);
    try {
      const auto n = static_cast<Eigen::Index>(gsl.y_.size());
      gsl.y_buffer_ = Eigen::Map<const Vec>(y, n);
      gsl.problem_->first_order_jacobian(t, gsl.y_buffer_, gsl.jacobian_);
      ++gsl.counters_.hessian_evals;
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          dfdy, n, n) = Eigen::MatrixXd(gsl.jacobian_);
      Eigen::Map<Vec> time_derivative(dfdt, n);
      time_derivative.setZero();
      if (gsl.problem_->has(kForce)) {
        const double delta = 1e-7 * std::max(1.0, std::abs(t));
        Vec plus, minus;
        gsl.problem_->first_order_rhs(t + delta, gsl.y_buffer_, plus);
        gsl.problem_->first_order_rhs(t - delta, gsl.y_buffer_, minus);
        gsl.counters_.force_evals += 2;
        time_derivative = (plus - minus) / (2 * delta);
      }
      return GSL_SUCCESS;
    } catch (const std::exception& error) {
      gsl.callback_error_ = error.what();
      return GSL_EBADFUNC;
    }
  }

  GslMethod method_;
  std::vector<double> y_;  // the solver's state of record (q, p)
  std::vector<double> ydot_start_;
  double h_ = 0.0;  // step size carried across calls
  gsl_odeiv2_system system_{};
  Vec y_buffer_, ydot_buffer_;
  SparseMatrix jacobian_;
  DriverPtr driver_;  // references system_, so it is declared (and destroyed) after it
};

std::unique_ptr<Integrator> make_gsl(Params& params, GslMethod method) {
  const AdaptiveSettings settings = read_adaptive_settings(
      params,
      "maximum number of accepted steps over the whole run (the run then fails with status "
      "max_steps)");
  return std::make_unique<GslOdeiv2>(method, settings);
}

}  // namespace

std::unique_ptr<Integrator> make_gsl_rk8pd(Params& params) {
  return make_gsl(params, GslMethod::kRk8pd);
}
std::unique_ptr<Integrator> make_gsl_msbdf(Params& params) {
  return make_gsl(params, GslMethod::kMsbdf);
}
std::unique_ptr<Integrator> make_gsl_rk4imp(Params& params) {
  return make_gsl(params, GslMethod::kRk4imp);
}

}  // namespace geomint
