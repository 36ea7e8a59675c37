// Implicit midpoint rule y₁ = y₀ + h f((y₀ + y₁)/2) on y = (q, p) with forces (Hairer, Lubich &
// Wanner, GNI §II.1 and §VI.3; docs/METHOD.md §1: for constant M it is the variational midpoint
// rule L_d = h L((q_k + q_{k+1})/2, v) and HP with α = ½; Marsden & West 2001, §2.6).
#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <vector>

#include "integrators/forcing.hpp"
#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "integrators/step_implementation.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// With q̄ = (q₀ + q₁)/2 and p̄ = (p₀ + p₁)/2 the rule reads q̄ − q₀ = (h/2)M⁻¹p̄ and
// p̄ = p₀ + (h/2)[−∇V(q̄) + F(q̄, M⁻¹p̄, t + h/2)]. The unknown is the midpoint velocity
// v̄ = M⁻¹p̄ = 2(q̄ − q₀)/h (q̄ itself up to an affine change of variables, which keeps the matrix
// M-scaled and symmetric):
//   R(v̄) = M v̄ − p₀ + (h/2)∇V(q₀ + (h/2)v̄) − (h/2)F(q₀ + (h/2)v̄, v̄, t + h/2) = 0,
//   ∂R/∂v̄ = M + (h²/4)∇²V(q̄) + (h/2)C(q̄, v̄)   (C = −∂F/∂v; the (h²/4)∂F/∂q part is left out as
//   in implicit_euler, or the whole force part is differenced without force_jacobian_v),
// then q₁ = q₀ + h v̄ and p₁ = 2M v̄ − p₀. Declared variational: for constant M this is exactly
// the DEL map of the midpoint discrete Lagrangian (del:rule=midpoint, hp:alpha=0.5), and with a
// force it is that map with F_d⁻ = F_d⁺ = (h/2)F(q̄, v̄) (force_slot=split, force_at=midpoint).
// On the general kind L = ½vᵀM(q)v + a(q)ᵀv − V(q) the same unknown and the same Newton solve:
// p̄ = L_v(q̄, v̄) is the midpoint momentum whose velocity is v̄, so the rule on z = (q, p) of the
// Hamiltonian view (docs/MECHANICS_GENERAL.md §3) reads
//   R(v̄) = L_v(q̄, v̄) − p₀ − (h/2)[L_q(q̄, v̄) + F] = 0,
//   ∂R/∂v̄ = M(q̄) + (h/2)(L_vq − L_qv) − (h²/4)L_qq   (not symmetric with a gyroscopic a(q)),
// then q₁ = q₀ + h v̄ and p₁ = 2p̄ − p₀ with p̄ = p₀ + (h/2)[L_q + F] = L_v(q̄, v̄) — the α = ½
// DEL map of the general L.
class ImplicitMidpoint final : public Integrator {
 public:
  explicit ImplicitMidpoint(const NewtonOptions& newton) : newton_(newton) {
    newton_.options().polish = true;  // momentum maps to round-off, not to the tolerance
  }

  MethodInfo info() const override {
    return {
        "implicit_midpoint", 2,
        kImplicit | kSymplectic | kSymmetric | kVariational | kNeedsHessian | kGeneralLagrangian,
        "implicit midpoint rule, GNI §II.1, §VI.3; Marsden-West 2001 §2.6; docs/METHOD.md §1"};
  }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::unconditional();  // |R(iy)| = 1 for every y (GNI §VI.4)
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    damping_symmetric_.reset();
  }

  // The one step of both kinds (integrators/step_implementation.hpp): they differ only in the
  // view asked at (q̄, v̄) — L_v = M v̄ through the mass operator and L_q = −∇V on the separable
  // kind, the problem's LagrangianSystem on the general one (momentum, lagrangian_q and, for the
  // Newton matrix, M(q̄), L_vq and L_qq).
  StepStatus step(const Problem& problem, State& state, double h) override {
    mark_step_implementation();
    const MassOperator mass(problem);
    const LagrangianSystem* general = problem.as_lagrangian();
    if (general == nullptr) update_sparse_mass_matrix(problem, mass_diagonal_, mass_matrix_);
    const bool forced = problem.has(kForce);
    const double t_mid = state.t + h / 2;
    // Start v̄ = v(q₀, p₀) = M⁻¹(p₀ − a(q₀)) (linear momentum exact through every iterate, as for
    // del and hp).
    Vec v = general != nullptr ? general->velocity(state.q, state.p) : mass.solve(state.q, state.p);
    if (forced) decide_damping_symmetry(problem, state.q, v, state.t, damping_, damping_symmetric_);

    // L_v(q̄, v̄) at q̄ = q₀ + (h/2)v̄: M(q̄)v̄ + a(q̄) on the general kind, M v̄ on the separable
    // one (the constant diagonal's product, which reads no q̄).
    const auto momentum = [&](const Vec& x, Vec& out) {
      if (general != nullptr) {
        out = general->momentum(state.q + (h / 2) * x, x);
      } else {
        mass.apply(state.q, x, out);
      }
    };
    // −(h/2)[L_q(q̄, v̄) + F(q̄, v̄, t + h/2)] (L_q = −∇V on the separable kind), the implicit part
    // of R, memoised on v̄ (the solver's first evaluation repeats the one for the residual scale).
    bool memo_valid = false;
    Vec memo_v;
    const auto impulse = [&](const Vec& x, Vec& out) {
      if (memo_valid && memo_v == x) return;
      memo_valid = true;
      memo_v = x;
      const Vec q_mid = state.q + (h / 2) * x;
      if (general != nullptr) {
        ++counters_.force_evals;
        general->lagrangian_q(q_mid, x, out);
        out = -out;
      } else {
        eval_gradient(problem, q_mid, out);
      }
      if (forced) {
        ++counters_.force_evals;
        eval_force(problem, q_mid, x, t_mid, force_);
        out -= force_;
      }
      out *= h / 2;
    };
    double inner_scale = 0.0;
    NewtonSystem system;
    system.inner_term_scale = [&] { return inner_scale; };
    system.residual = [&](const Vec& x, Vec& residual) {
      impulse(x, impulse_);
      momentum(x, momentum_);
      residual = momentum_ - state.p + impulse_;
    };
    system.jacobian = [&](const Vec& x, SparseMatrix& jacobian) {
      const Vec q_mid = state.q + (h / 2) * x;
      if (general != nullptr) {
        general_jacobian(*general, q_mid, x, h, jacobian);
        inner_scale =
            std::abs(h / 2) * robust_norm((lagrangian_qq_.cwiseAbs() * q_mid.cwiseAbs()).eval());
      } else {
        eval_hessian(problem, q_mid, hessian_);
        inner_scale = std::abs(h / 2) * gradient_term_scale(hessian_, q_mid);
        jacobian = mass_matrix_ + (h * h / 4) * hessian_;
      }
      if (!forced) return;
      if (problem.has(kForceJacobian)) {
        force_of(problem).force_jacobian_v(q_mid, x, t_mid, damping_);
        jacobian += (h / 2) * damping_;
      } else {
        jacobian -= (h / 2) * central_difference_jacobian(
                                  [&](const Vec& y, Vec& f) {
                                    eval_force(problem, state.q + (h / 2) * y, y, t_mid, f);
                                  },
                                  x);
        counters_.force_evals += 2 * x.size();
      }
    };
    // The general kind's matrix has the non-symmetric part (h/2)(L_vq − L_qv).
    system.symmetric =
        general == nullptr && (!forced || (problem.has(kForceJacobian) && *damping_symmetric_));

    impulse(v, impulse_);
    const double residual_scale = robust_norm(state.p) + robust_norm(impulse_);
    const NewtonResult result = newton_.solve(system, v, residual_scale);
    counters_.newton_iters += result.iterations;
    counters_.linear_solves += result.linear_solves;
    counters_.factorizations += result.factorizations;
    if (!result.converged) return StepStatus::failure(result.reason, describe(result));

    // p₁ = 2p̄ − p₀. On the general kind p̄ = p₀ + (h/2)[L_q + F] at the accepted v̄ (equal to
    // L_v(q̄, v̄) up to the residual), which keeps the momentum of a cyclic coordinate (L_q ≡ 0:
    // polar Kepler's p_φ) exact whatever residual the solve left, as the rule on z = (q, p) does.
    if (general != nullptr) {
      impulse(v, impulse_);
      state.p -= 2 * impulse_;
    } else {
      momentum(v, momentum_);
      state.p = 2 * momentum_ - state.p;
    }
    state.q += h * v;
    state.t += h;
    ++counters_.steps;
    return StepStatus::success();
  }

  // Unforced, p₁ = 2M v̄ − p₀ = M v̄ − (h/2)∇V(q̄): the DEL map of the midpoint node (½, 1)
  // (integrators/tangent.hpp) at v̄ = (q₁ − q₀)/h.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const Vec q0 = state.q;
    const StepStatus status = step(problem, state, h);
    if (status.ok) {
      tangent = quadrature_del_tangent(problem, q0, state.q, (state.q - q0) / h, h, {{0.5, 1.0}});
    }
    return status;
  }

 private:
  // ∂R/∂v̄ on the general kind, R = L_v(q̄, v̄) − p₀ − (h/2)L_q(q̄, v̄) with q̄ = q₀ + (h/2)v̄:
  // M(q̄) + (h/2)(L_vq − L_qv) − (h²/4)L_qq (on the separable kind M + (h²/4)∇²V). Every entry is
  // stored, zeros included, so the solver keeps one sparsity pattern per run.
  void general_jacobian(const LagrangianSystem& general, const Vec& q_mid, const Vec& v, double h,
                        SparseMatrix& jacobian) {
    general.mass_matrix(q_mid, dense_jacobian_);
    general.lagrangian_vq(q_mid, v, lagrangian_vq_);
    general.lagrangian_qq(q_mid, v, lagrangian_qq_);
    dense_jacobian_ +=
        (h / 2) * (lagrangian_vq_ - lagrangian_vq_.transpose()) - (h * h / 4) * lagrangian_qq_;
    const Eigen::Index n = dense_jacobian_.rows();
    triplets_.clear();
    triplets_.reserve(static_cast<size_t>(n * n));
    for (Eigen::Index j = 0; j < n; ++j) {
      for (Eigen::Index i = 0; i < n; ++i) triplets_.emplace_back(i, j, dense_jacobian_(i, j));
    }
    jacobian.resize(n, n);
    jacobian.setFromTriplets(triplets_.begin(), triplets_.end());
  }

  NewtonSolver newton_;
  Vec mass_diagonal_;
  SparseMatrix mass_matrix_, hessian_, damping_;
  std::optional<bool> damping_symmetric_;
  Vec impulse_, force_, momentum_;
  DenseMatrix dense_jacobian_, lagrangian_vq_, lagrangian_qq_;
  std::vector<Eigen::Triplet<double>> triplets_;
};

}  // namespace

std::unique_ptr<Integrator> make_implicit_midpoint(Params& params) {
  const NewtonOptions newton = read_newton_options(params, "|p| + h|F|/2");
  return std::make_unique<ImplicitMidpoint>(newton);
}

}  // namespace geomint
