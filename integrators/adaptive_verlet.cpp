// Störmer–Verlet with a standard error controller (Hairer, Lubich & Wanner, GNI §VIII.1): the
// contrast that shows why a symplectic step with state-dependent step sizes loses the bounded
// energy error of the fixed-step method (docs/METHOD.md §1; docs/METHODS.md "Adaptive steps against
// structure").
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>

#include "integrators/adaptive.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// Each attempt is one kick–drift–kick of size h from (q, p), with the "Verlet with forces"
// treatment of stormer_verlet for F. The local error is estimated against the embedded
// symplectic Euler (kick–drift) solution, which uses the same two force evaluations:
//   q̂ = q + h M⁻¹(p + h f₀),  p̂ = p + h f₀,   err = ‖(q⁺ − q̂, p⁺ − p̂)‖,
// of order h² (the first-order method's local error), so the controller is
// h_new = h · min(5, max(0.2, 0.9 · err^(−1/2))) in the weighted RMS norm with rtol|y| + atol
// (Hairer, Nørsett & Wanner I, §II.4). A rejected attempt is retried with the smaller h.
// Every accepted step is a symplectic map, but the sequence of them is not one map of the state
// (h depends on the state), so nothing keeps the energy error bounded: GNI §VIII.1 shows it
// drifting linearly on Kepler. The force at the accepted q⁺ is carried to the next step (FSAL).
class AdaptiveVerlet final : public AdaptiveIntegrator {
 public:
  explicit AdaptiveVerlet(const AdaptiveSettings& settings)
      : AdaptiveIntegrator(settings, "adaptive_verlet") {}

  MethodInfo info() const override {
    return {"adaptive_verlet", 2, kExplicit | kAdaptive,
            "Stormer-Verlet with an embedded symplectic-Euler error estimate and a standard "
            "controller, GNI §VIII.1; docs/METHOD.md §1"};
  }

  void reset(const Problem& problem, const State& state, double h) override {
    begin_adaptive_reset(problem, state, h);
    q_ = state.q;
    p_ = state.p;
    force_valid_ = false;
    dt_ = 0.0;
  }

  // The problem's own exceptions (a force that throws) end the run as a failed status, as they
  // do inside the library wrappers' callbacks.
  StepStatus adaptive_step(const Problem& problem, State& state, double t_stop) override {
    try {
      return controlled_step(problem, state, t_stop);
    } catch (const std::exception& error) {
      return StepStatus::failure("exception", error.what());
    }
  }

 private:
  StepStatus controlled_step(const Problem& problem, State& state, double t_stop) {
    StepStatus status;
    if (!ready_to_step(problem, state, t_stop, status)) return status;
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    y_.resize(2 * q_.size());
    y_ << q_, p_;
    status = check_tolerances_above_roundoff(y_.data(), y_.size(), "too_much_accuracy",
                                             "adaptive_verlet");
    if (!status.ok) return status;
    if (!force_valid_) {
      eval_total_force(problem, q_, inverse_mass.cwiseProduct(p_), t_, force_);
      force_valid_ = true;
      if (dt_ == 0.0) {
        Vec rate(y_.size());
        rate << inverse_mass.cwiseProduct(p_), force_;
        dt_ = starting_step(y_, rate, settings_.rtol, settings_.atol);
      }
    }
    constexpr int kMaxAttempts = 500;  // as the odeint wrappers: then the step has underflowed
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      // A step that would leave a sliver of less than 1% before t_stop is stretched to land on it.
      const bool landing = t_ + 1.01 * dt_ >= t_stop;
      const double h = landing ? t_stop - t_ : dt_;
      if (!(h > 0) || t_ + h == t_) {
        return StepStatus::failure("step_underflow",
                                   fmt::format("step size {:g} underflows at t={:.17g}", h, t_));
      }
      half_p_ = p_ + (h / 2) * force_;
      next_q_ = q_ + h * inverse_mass.cwiseProduct(half_p_);
      eval_total_force(problem, next_q_, inverse_mass.cwiseProduct(half_p_), t_ + h, next_force_);
      next_p_ = half_p_ + (h / 2) * next_force_;
      // Verlet minus symplectic Euler: q differs by −(h²/2) M⁻¹f₀, p by (h/2)(f₁ − f₀).
      const double error = error_norm(h, inverse_mass);
      if (!std::isfinite(error)) {
        return StepStatus::failure("nan", fmt::format("non-finite step at t={:.17g}", t_));
      }
      const double factor = std::clamp(0.9 / std::sqrt(std::max(error, 1e-300)), 0.2, 5.0);
      if (error > 1.0) {
        ++counters_.rejected;
        dt_ = h * std::min(factor, 0.9);
        continue;
      }
      ++counters_.steps;
      t_ = landing ? t_stop : t_ + h;
      q_.swap(next_q_);
      p_.swap(next_p_);
      force_.swap(next_force_);
      // After a stretched landing step the proposal reflects the short step; keep the larger.
      dt_ = landing ? std::max(dt_, h * factor) : h * factor;
      state.t = t_;
      state.q = q_;
      state.p = p_;
      return StepStatus::success();
    }
    return StepStatus::failure(
        "max_attempts",
        fmt::format("{} rejected attempts in a row at t={:.17g}", kMaxAttempts, t_));
  }

  // Weighted RMS norm of the Verlet − symplectic Euler difference, weights rtol·max(|y|, |y⁺|) +
  // atol.
  double error_norm(double h, const Vec& inverse_mass) const {
    const long n = q_.size();
    double sum = 0.0;
    for (long i = 0; i < n; ++i) {
      const double dq = -(h * h / 2) * inverse_mass[i] * force_[i];
      const double dp = (h / 2) * (next_force_[i] - force_[i]);
      const double wq =
          settings_.rtol * std::max(std::abs(q_[i]), std::abs(next_q_[i])) + settings_.atol;
      const double wp =
          settings_.rtol * std::max(std::abs(p_[i]), std::abs(next_p_[i])) + settings_.atol;
      sum += (dq / wq) * (dq / wq) + (dp / wp) * (dp / wp);
    }
    return std::sqrt(sum / static_cast<double>(2 * n));
  }

  Vec q_, p_, force_, half_p_, next_q_, next_p_, next_force_, y_;
  bool force_valid_ = false;
  double dt_ = 0.0;  // the controller's current step size
};

}  // namespace

std::unique_ptr<Integrator> make_adaptive_verlet(Params& params) {
  return std::make_unique<AdaptiveVerlet>(read_adaptive_settings(
      params,
      "maximum number of accepted steps over the whole run (the run then fails with status "
      "max_steps)"));
}

}  // namespace geomint
