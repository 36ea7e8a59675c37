// Störmer–Verlet, kick–drift–kick (velocity Verlet): the VI of L_d = (h/2)[L(q_k, v) +
// L(q_{k+1}, v)] (docs/METHOD.md §1; Hairer, Lubich & Wanner, GNI §I.1.4 and §VI.3, eq. (3.4)).
#include "integrators/fixed_step_loop.hpp"
#include "integrators/integrator.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// One unforced kick–drift–kick with g = ∇V(q) on entry and ∇V(q⁺) on exit: the arithmetic of
// step() and of both advance() loops, on dynamic or fixed-size vectors alike.
template <class V, class Gradient>
inline void kick_drift_kick(V& q, V& p, V& g, const V& inverse_mass, double h,
                            Gradient&& gradient) {
  p -= (h / 2) * g;
  q += h * inverse_mass.cwiseProduct(p);
  gradient(q, g);
  p -= (h / 2) * g;
}

// The whole grid without a visitor on fixed-size copies of q, p and ∇V that live only in this
// loop, so that the compiler keeps them in registers and inlines the gradient.
template <class Gradient>
void fixed_size_loop(const Gradient& gradient, const Vec& inverse_mass, const StepGrid& grid,
                     State& state, Vec& g_at_q) {
  using Fixed = Eigen::Matrix<double, Gradient::kDof, 1>;
  const Fixed fixed_inverse_mass = inverse_mass;
  Fixed q = state.q, p = state.p, g = g_at_q;
  double t = state.t;
  for (long k = 1; k <= grid.n; ++k) {
    const double t_next = grid.time(k);
    kick_drift_kick(q, p, g, fixed_inverse_mass, t_next - t, gradient);
    t = t_next;
  }
  state.t = t;
  state.q = q;
  state.p = p;
  g_at_q = g;
}

//   p½ = p + (h/2)[−∇V(q) + F(q, M⁻¹p, t)]
//   q⁺ = q + h M⁻¹p½
//   p⁺ = p½ + (h/2)[−∇V(q⁺) + F(q⁺, M⁻¹p⁺, t + h)]
// Without F this is symmetric, symplectic and second order. A velocity-dependent F makes the
// last half-kick implicit in v⁺ = M⁻¹p⁺; it is solved by fixed-point iteration
// (Integrator::solve_force_kick: no Jacobian, no linear solve, converging wherever the step is
// stable for the damping), which keeps the method second order and the two half-kicks adjoint
// (tests/methods_test.cpp, DeclaredOrderWithATimeDependentForce). Taking F at the half-step
// velocity M⁻¹p½ instead ("Verlet with forces", explicit) is only first order for a
// velocity-dependent F — measured 1.05 on the driven damped oscillator. A force that does not
// depend on v costs one more evaluation and gives the same bits.
//
// First same as last: ∇V(q⁺) of one step is ∇V(q) of the next, so after the first step each
// step costs one gradient. The cached gradient is used only when the incoming q is bitwise the
// q⁺ it was computed at (and the problem is the same object), so a caller that edits the state
// between steps gets a fresh evaluation, never a stale one. advance() checks the cache once, then
// carries the gradient from step to step itself; without a visitor (the harness's timing pass), on
// problems that offer a fixed gradient, it runs the unforced loop on fixed-size vectors with the
// gradient inlined.
//
// `compensated=true` (GNI §VIII.5, Kahan's compensated summation): the same step written as
// increments δq = h M⁻¹p½ and δp = (h/2)(f(q) + f(q⁺)), each added to the state with the lost
// low-order bits carried in error_q_/error_p_ to the next step, so that round-off in the sum
// q + δq stops growing like √N (Brouwer's law). The carried errors belong to the run: a state
// edited between steps (the cache check on q and p) starts them again from zero.
class StormerVerlet final : public Integrator {
 public:
  explicit StormerVerlet(bool compensated) : compensated_(compensated) {}

  MethodInfo info() const override {
    return {"stormer_verlet", 2, kExplicit | kSymplectic | kSymmetric | kVariational,
            "Stormer-Verlet (velocity Verlet), GNI §I.1.4, §VI.3; docs/METHOD.md §1"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // trace of the step matrix 2 − (hω)² (GNI §I.5)
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    cached_problem_ = nullptr;
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    const bool cache_hit = prime_gradient(problem, state);
    StepStatus status;
    if (compensated_) {
      status = compensated_step(problem, state, h, cache_hit);
    } else if (problem.has(kForce)) {
      status = forced_step(problem, state, h, cache_hit);
    } else {
      kick_drift_kick(state.q, state.p, gradient_,
                      MassOperator(problem).constant_inverse_diagonal(), h, counted(problem));
      state.t += h;
    }
    remember(problem, state);
    if (!status.ok) return status;
    ++counters_.steps;
    return status;
  }

  // Kick with ∇²V(q), drift, kick with ∇²V(q⁺); compensated summation changes only rounding.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    TangentBlock block(problem.dof());
    block.kick(dense_hessian(problem, state.q), h / 2);
    block.drift(MassOperator(problem).constant_inverse_diagonal(), h);
    const StepStatus status = step(problem, state, h);
    block.kick(dense_hessian(problem, state.q), h / 2);
    tangent = block.stacked();
    return status;
  }

  AdvanceOutcome advance(const Problem& problem, State& state, const StepGrid& grid,
                         StepVisitor visit) override {
    AdvanceOutcome outcome;
    if (compensated_) {
      bool cache_hit = prime_gradient(problem, state);
      outcome = run_grid(state, grid, visit, [&](double h) {
        StepStatus status = compensated_step(problem, state, h, cache_hit);
        cache_hit = true;
        if (status.ok) ++counters_.steps;
        return status;
      });
      remember(problem, state);
      return outcome;
    }
    if (problem.has(kForce)) {
      bool cache_hit = prime_gradient(problem, state);
      outcome = run_grid(state, grid, visit, [&](double h) {
        StepStatus status = forced_step(problem, state, h, cache_hit);
        cache_hit = true;  // as step() finds it after a step of its own
        if (status.ok) ++counters_.steps;
        return status;
      });
      remember(problem, state);
      return outcome;
    }
    prime_gradient(problem, state);
    const bool fixed = !visit && with_fixed_gradient(problem, [&](const auto& gradient) {
      fixed_size_loop(gradient, MassOperator(problem).constant_inverse_diagonal(), grid, state,
                      gradient_);
      counters_.force_evals += grid.n;
      counters_.steps += grid.n;
      outcome.steps = grid.n;
    });
    if (!fixed) {
      const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
      outcome = run_grid(state, grid, visit, [&](double h) {
        kick_drift_kick(state.q, state.p, gradient_, inverse_mass, h, counted(problem));
        ++counters_.steps;
      });
    }
    remember(problem, state);
    return outcome;
  }

 private:
  // Makes gradient_ = ∇V(state.q), from the cache when it holds; returns whether it did.
  bool prime_gradient(const Problem& problem, const State& state) {
    const bool cache_hit =
        cached_problem_ == &problem && cached_q_.size() == state.q.size() && cached_q_ == state.q;
    if (!cache_hit) eval_gradient(problem, state.q, gradient_);
    if (compensated_ && !(cache_hit && cached_p_ == state.p)) {
      error_q_ = Vec::Zero(state.q.size());
      error_p_ = Vec::Zero(state.p.size());
    }
    return cache_hit;
  }
  void remember(const Problem& problem, const State& state) {
    cached_problem_ = &problem;
    cached_q_ = state.q;
    if (compensated_) cached_p_ = state.p;
  }

  // y ← y + δ with Kahan's compensation e (GNI §VIII.5, Algorithm 5.1): a = δ + e, y⁺ = y + a,
  // e = (y − y⁺) + a. Needs IEEE evaluation order (no -ffast-math, as the build guarantees).
  static void compensated_add(Vec& y, const Vec& increment, Vec& error) {
    for (Eigen::Index i = 0; i < y.size(); ++i) {
      const double a = increment[i] + error[i];
      const double sum = y[i] + a;
      error[i] = (y[i] - sum) + a;
      y[i] = sum;
    }
  }

  // One kick–drift–kick as increments (gradient_ = ∇V(q) on entry, ∇V(q⁺) on exit); forces as
  // in forced_step.
  StepStatus compensated_step(const Problem& problem, State& state, double h, bool cache_hit) {
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    const bool forced = problem.has(kForce);
    increment_p_ = -(h / 2) * gradient_;
    if (forced) {
      velocity_ = inverse_mass.cwiseProduct(state.p);
      eval_force(problem, state.q, velocity_, state.t, force_);
      if (cache_hit) ++counters_.force_evals;
      increment_p_ += (h / 2) * force_;
    }
    half_p_ = state.p + increment_p_;
    increment_q_ = h * inverse_mass.cwiseProduct(half_p_);
    compensated_add(state.q, increment_q_, error_q_);
    state.t += h;
    eval_gradient(problem, state.q, gradient_);
    increment_p_ -= (h / 2) * gradient_;
    if (forced) {
      velocity_ = inverse_mass.cwiseProduct(half_p_);
      base_p_ = state.p + increment_p_;
      StepStatus status =
          solve_force_kick(problem, state.q, state.t, base_p_, h / 2, velocity_, force_);
      if (!status.ok) return status;
      increment_p_ += (h / 2) * force_;
    }
    compensated_add(state.p, increment_p_, error_p_);
    return StepStatus::success();
  }
  // ∇V through eval_gradient, so that the dynamic loops count their evaluations.
  struct CountedGradient {
    StormerVerlet* method;
    const Problem* problem;
    void operator()(const Vec& q, Vec& g) const { method->eval_gradient(*problem, q, g); }
  };
  CountedGradient counted(const Problem& problem) { return {this, &problem}; }

  StepStatus forced_step(const Problem& problem, State& state, double h, bool cache_hit) {
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    velocity_ = inverse_mass.cwiseProduct(state.p);
    eval_force(problem, state.q, velocity_, state.t, force_);
    // eval_force is not counted; it is a force-field evaluation of its own when the gradient
    // at this point came from the cache.
    if (cache_hit) ++counters_.force_evals;
    state.p -= (h / 2) * gradient_;
    state.p += (h / 2) * force_;
    state.q += h * inverse_mass.cwiseProduct(state.p);
    state.t += h;
    eval_gradient(problem, state.q, gradient_);
    velocity_ = inverse_mass.cwiseProduct(state.p);  // the guess: the half-step velocity
    base_p_ = state.p - (h / 2) * gradient_;
    StepStatus status =
        solve_force_kick(problem, state.q, state.t, base_p_, h / 2, velocity_, force_);
    if (!status.ok) return status;
    state.p += (h / 2) * force_;
    state.p -= (h / 2) * gradient_;
    return StepStatus::success();
  }

  const bool compensated_;
  const Problem* cached_problem_ = nullptr;
  Vec cached_q_;  // q at which gradient_ = ∇V(q) was evaluated
  Vec cached_p_;  // p after the last compensated step (its errors belong to that state)
  Vec gradient_, force_, velocity_, base_p_;
  Vec error_q_, error_p_, increment_q_, increment_p_, half_p_;  // compensated summation
};

}  // namespace

std::unique_ptr<Integrator> make_stormer_verlet(Params& params) {
  const bool compensated = params.flag(
      "compensated", false,
      "add the step's increments to q and p with Kahan's compensated summation (GNI §VIII.5)");
  params.omit_default_from_canonical("compensated");
  return std::make_unique<StormerVerlet>(compensated);
}

}  // namespace geomint
