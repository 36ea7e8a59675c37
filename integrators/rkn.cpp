// Explicit Runge–Kutta–Nyström methods for q'' = −M⁻¹∇V(q) (Hairer, Nørsett & Wanner I, §II.14):
// fixed-step `rkn:table=` and the embedded FSAL pairs of Dormand, El-Mikkawy & Prince (1987) with a
// step-size controller, `rkn_adaptive:pair=`; coefficients in rkn_coefficients.hpp.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "integrators/adaptive.hpp"
#include "integrators/rkn_coefficients.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

using coefficients::RknTable;

std::vector<double> to_double(const std::vector<long double>& values) {
  return {values.begin(), values.end()};
}

// The stages of one RKN step on (q, p = Mv), shared by both families. The stages use ∇V only, so
// a force F(q, v, t) has no place in them: the methods are kConservativeOnly.
class RknStages {
 public:
  explicit RknStages(const RknTable& table)
      : table_(table),
        c_(to_double(table.c)),
        bbar_(to_double(table.bbar)),
        b_(to_double(table.b)),
        bbar_hat_(to_double(table.bbar_hat)),
        b_hat_(to_double(table.b_hat)),
        fsal_(table.fsal()) {
    for (const auto& row : table.abar) abar_.push_back(to_double(row));
  }

  const RknTable& table() const { return table_; }
  bool fsal() const { return fsal_; }
  int stages() const { return static_cast<int>(c_.size()); }

  // One attempt of size h from (q, p); gradients_[0] must hold ∇V(q). Fills next_q_, next_p_ and
  // (FSAL) gradients_.back() = ∇V(next_q_). `gradient` evaluates ∇V and counts it.
  template <class Gradient>
  void attempt(const Vec& q, const Vec& p, const Vec& inverse_mass, double h, Gradient gradient) {
    const int s = stages();
    gradients_.resize(s);
    velocity_ = inverse_mass.cwiseProduct(p);
    for (int i = 1; i < s; ++i) {
      // Q_i = q + c_i h v − h² M⁻¹ Σ_j abar_ij ∇V(Q_j); the FSAL stage is built exactly as q⁺ is.
      sum_.setZero(q.size());
      for (int j = 0; j < i; ++j) {
        if (abar_[i][j] != 0) sum_ += abar_[i][j] * gradients_[j];
      }
      stage_q_ = q + (c_[i] * h) * velocity_ - (h * h) * inverse_mass.cwiseProduct(sum_);
      gradient(stage_q_, gradients_[i]);
    }
    if (fsal_) {
      next_q_ = stage_q_;
    } else {
      sum_.setZero(q.size());
      for (int i = 0; i < s; ++i) {
        if (bbar_[i] != 0) sum_ += bbar_[i] * gradients_[i];
      }
      next_q_ = q + h * velocity_ - (h * h) * inverse_mass.cwiseProduct(sum_);
    }
    sum_.setZero(q.size());
    for (int i = 0; i < s; ++i) {
      if (b_[i] != 0) sum_ += b_[i] * gradients_[i];
    }
    next_p_ = p - h * sum_;
  }

  // Weighted RMS norm of the main minus the embedded solution, weights rtol·max(|y|, |y⁺|) + atol
  // (Hairer, Nørsett & Wanner I, §II.4).
  double error_norm(const Vec& q, const Vec& p, const Vec& inverse_mass, double h, double rtol,
                    double atol) {
    const int s = stages();
    dq_.setZero(q.size());
    dp_.setZero(q.size());
    for (int i = 0; i < s; ++i) {
      dq_ += (bbar_[i] - bbar_hat_[i]) * gradients_[i];
      dp_ += (b_[i] - b_hat_[i]) * gradients_[i];
    }
    double sum = 0.0;
    for (long k = 0; k < q.size(); ++k) {
      const double eq = h * h * inverse_mass[k] * dq_[k];
      const double ep = h * dp_[k];
      const double wq = rtol * std::max(std::abs(q[k]), std::abs(next_q_[k])) + atol;
      const double wp = rtol * std::max(std::abs(p[k]), std::abs(next_p_[k])) + atol;
      sum += (eq / wq) * (eq / wq) + (ep / wp) * (ep / wp);
    }
    return std::sqrt(sum / static_cast<double>(2 * q.size()));
  }

  std::vector<Vec> gradients_;
  Vec next_q_, next_p_;

 private:
  const RknTable& table_;
  std::vector<double> c_, bbar_, b_, bbar_hat_, b_hat_;
  std::vector<std::vector<double>> abar_;
  bool fsal_;
  Vec velocity_, sum_, stage_q_, dq_, dp_;
};

StepStatus force_refusal(const std::string& method, const Problem& problem) {
  return StepStatus::failure(
      "unsupported_force",
      fmt::format("{} integrates q'' = -M^-1 grad V(q) only; problem '{}' has a non-conservative "
                  "force",
                  method, problem.name()));
}

// Fixed step. With an FSAL table ∇V(q⁺) of one step is the first stage of the next, as long as the
// next step starts from the bitwise same q (a caller that edits the state gets a fresh gradient).
class Rkn final : public Integrator {
 public:
  explicit Rkn(const RknTable& table) : stages_(table) {}

  MethodInfo info() const override {
    const RknTable& table = stages_.table();
    return {"rkn", table.order, kExplicit | kConservativeOnly,
            fmt::format("explicit Runge-Kutta-Nystrom, {} stages{} ({})", table.c.size(),
                        stages_.fsal() ? ", FSAL" : "", table.source)};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "no formula in geomint: the interval of periodicity of the table's stability matrix is "
        "not derived here");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    cached_problem_ = nullptr;
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (problem.has(kForce)) return force_refusal("rkn", problem);
    stages_.gradients_.resize(stages_.stages());
    const bool reuse = stages_.fsal() && cached_problem_ == &problem &&
                       cached_q_.size() == state.q.size() && cached_q_ == state.q;
    if (reuse) {
      stages_.gradients_[0].swap(stages_.gradients_.back());
    } else {
      eval_gradient(problem, state.q, stages_.gradients_[0]);
    }
    stages_.attempt(state.q, state.p, MassOperator(problem).constant_inverse_diagonal(), h,
                    [&](const Vec& q, Vec& g) { eval_gradient(problem, q, g); });
    state.q.swap(stages_.next_q_);
    state.p.swap(stages_.next_p_);
    state.t += h;
    if (stages_.fsal()) {
      cached_problem_ = &problem;
      cached_q_ = state.q;
    }
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  RknStages stages_;
  const Problem* cached_problem_ = nullptr;
  Vec cached_q_;  // q at which gradients_.back() = ∇V(q) was evaluated
};

// The embedded pair with the controller of adaptive_verlet: h_new = h · clamp(0.9 · err^(−1/(p̂+1)),
// 0.2, 5) with p̂ the embedded order, a rejected attempt retried with the smaller h, and the FSAL
// gradient carried to the next step (s − 1 gradients per attempt after the first).
class RknAdaptive final : public AdaptiveIntegrator {
 public:
  RknAdaptive(const RknTable& table, const AdaptiveSettings& settings)
      : AdaptiveIntegrator(settings, "rkn_adaptive"), stages_(table) {}

  MethodInfo info() const override {
    const RknTable& table = stages_.table();
    return {"rkn_adaptive", table.order, kExplicit | kAdaptive | kConservativeOnly,
            fmt::format("embedded Runge-Kutta-Nystrom pair {}({}), {} stages, FSAL, standard "
                        "step-size controller ({})",
                        table.order, table.embedded_order, table.c.size(), table.source)};
  }

  void reset(const Problem& problem, const State& state, double h) override {
    begin_adaptive_reset(problem, state, h);
    q_ = state.q;
    p_ = state.p;
    gradient_valid_ = false;
    dt_ = 0.0;
  }

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
    if (problem.has(kForce)) return force_refusal("rkn_adaptive", problem);
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    y_.resize(2 * q_.size());
    y_ << q_, p_;
    status =
        check_tolerances_above_roundoff(y_.data(), y_.size(), "too_much_accuracy", "rkn_adaptive");
    if (!status.ok) return status;
    auto& gradients = stages_.gradients_;
    gradients.resize(stages_.stages());
    if (!gradient_valid_) {
      eval_gradient(problem, q_, gradients[0]);
      gradient_valid_ = true;
      if (dt_ == 0.0) {
        Vec rate(y_.size());
        rate << inverse_mass.cwiseProduct(p_), -gradients[0];
        dt_ = starting_step(y_, rate, settings_.rtol, settings_.atol);
      }
    }
    const double exponent = -1.0 / (stages_.table().embedded_order + 1);
    constexpr int kMaxAttempts = 500;  // as adaptive_verlet: then the step has underflowed
    for (int attempt = 0; attempt < kMaxAttempts; ++attempt) {
      // A step that would leave a sliver of less than 1% before t_stop is stretched to land on it.
      const bool landing = t_ + 1.01 * dt_ >= t_stop;
      const double h = landing ? t_stop - t_ : dt_;
      if (!(h > 0) || t_ + h == t_) {
        return StepStatus::failure("step_underflow",
                                   fmt::format("step size {:g} underflows at t={:.17g}", h, t_));
      }
      stages_.attempt(q_, p_, inverse_mass, h,
                      [&](const Vec& q, Vec& g) { eval_gradient(problem, q, g); });
      const double error =
          stages_.error_norm(q_, p_, inverse_mass, h, settings_.rtol, settings_.atol);
      if (!std::isfinite(error)) {
        return StepStatus::failure("nan", fmt::format("non-finite step at t={:.17g}", t_));
      }
      const double factor = std::clamp(0.9 * std::pow(std::max(error, 1e-300), exponent), 0.2, 5.0);
      if (error > 1.0) {
        ++counters_.rejected;
        dt_ = h * std::min(factor, 0.9);
        continue;
      }
      ++counters_.steps;
      t_ = landing ? t_stop : t_ + h;
      q_.swap(stages_.next_q_);
      p_.swap(stages_.next_p_);
      gradients[0].swap(gradients.back());  // FSAL: ∇V(q⁺)
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

  RknStages stages_;
  Vec q_, p_, y_;
  bool gradient_valid_ = false;
  double dt_ = 0.0;  // the controller's current step size
};

std::vector<std::string> table_names(bool embedded_only) {
  std::vector<std::string> names;
  for (const auto& table : coefficients::rkn_tables()) {
    if (!embedded_only || table.embedded_order > 0) names.emplace_back(table.name);
  }
  return names;
}

const RknTable& find_table(const std::string& name) {
  for (const auto& table : coefficients::rkn_tables()) {
    if (table.name == name) return table;
  }
  throw InputError("rkn: unknown table=" + name);  // unreachable: choice() checked it
}

}  // namespace

std::unique_ptr<Integrator> make_rkn(Params& params) {
  const std::string name = params.choice(
      "table", "dprkn6", table_names(false),
      "coefficients (order, stages): nystrom4 (4, 3), dprkn4 (4, 4 FSAL), dprkn5 (5, 6 FSAL), "
      "dprkn6 (6, 6 FSAL), dprkn8 (8, 9 FSAL): Nystrom's classical method and the higher-order "
      "solutions of Dormand, El-Mikkawy & Prince's pairs, used with a fixed step");
  return std::make_unique<Rkn>(find_table(name));
}

std::unique_ptr<Integrator> make_rkn_adaptive(Params& params) {
  const std::string name = params.choice(
      "pair", "dprkn6", table_names(true),
      "embedded pair (orders): dprkn4 (4(3)), dprkn5 (5(4)), dprkn6 (6(4)), dprkn8 (8(6)): "
      "Dormand, El-Mikkawy & Prince 1987, FSAL");
  const AdaptiveSettings settings = read_adaptive_settings(
      params,
      "maximum number of accepted steps over the whole run (the run then fails with status "
      "max_steps)");
  return std::make_unique<RknAdaptive>(find_table(name), settings);
}

}  // namespace geomint
