// RATTLE (Andersen 1983; GNI §VII.1.4; Leimkuhler & Skeel 1994): Störmer–Verlet with holonomic
// constraints g(q) = 0 — SHAKE's position projection by a Newton solve for the position
// multipliers, then a linear solve for the velocity multipliers (docs/METHOD.md §3).
#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "integrators/general_constrained_step.hpp"
#include "integrators/integrator.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

//   p½ = p + (h/2)[−∇V(q) + F(q, M⁻¹p, t)] − (h/2) G(q)ᵀλ
//   q⁺ = q + h M⁻¹p½,                  g(q⁺) = 0              (m equations for λ)
//   p⁺ = p½ + (h/2)[−∇V(q⁺) + F(q⁺, M⁻¹p½, t + h)] − (h/2) G(q⁺)ᵀμ,  G(q⁺) M⁻¹p⁺ = 0  (μ)
// Without F this is symmetric, symplectic on the constraint manifold's cotangent bundle and of
// order 2 (GNI Theorem VII.1.5); it is the constrained discrete Euler–Lagrange map of the
// Störmer–Verlet discrete Lagrangian (Marsden & West 2001 §3.5), hence kVariational. Forces
// follow stormer_verlet's convention (half-step velocity in the second kick).
//
// The position multipliers enter as Λ = (h²/2)λ, q⁺ = q̃ − M⁻¹G(q)ᵀΛ with q̃ the unconstrained
// drift; Newton on g(q⁺(Λ)) = 0 solves (G(q⁺) M⁻¹ G(q)ᵀ) ΔΛ = g(q⁺) — the exact Jacobian, so
// the iteration converges quadratically. It stops when ‖g(q⁺)‖∞ ≤ tol·‖G(q⁺)‖∞‖q⁺‖∞: g is a
// difference of coordinates of size ‖q⁺‖∞, so this is round-off relative to the state's own
// scale, with no absolute floor. The budget max_iter ends a step as "rattle_max_iter", never a
// hang. `velocity_projection=false` skips the μ solve (plain SHAKE velocities): the position
// sequence is unchanged (the next λ absorbs the normal part of p), but the reported p leaves the
// tangent space at O(h) — the negative control of the velocity-level constraint metric.
//
// Rheonomic constraints g(q, t) = 0 (car_axis; kRheonomic) are the same map in the extended
// configuration (q, t) with t advanced exactly (Jay 1996; GNI §VII.1.4 with t as a coordinate):
// G at each end is taken at that end's time, the position constraint is g(q⁺, t + h) = 0 and the
// velocity one G(q⁺, t + h) M⁻¹p⁺ + ∂g/∂t(q⁺, t + h) = 0. The step stays symmetric, so the
// compositions over it keep their orders. Time-free problems take the time-free calls, so their
// results stay bit-identical.
//
// The m × m systems are dense: every catalogue problem has a few constraints (rods, pins), and
// for them a dense LU/LDLᵀ costs less than a sparse analysis per step.
//
// A position-dependent mass (the general Lagrangian kind, kGeneralLagrangian: andrews) takes the
// same map in its general form: the constrained DEL step of the trapezoidal (Störmer–Verlet)
// discrete Lagrangian L_d = (h/2)[L(q, v) + L(q⁺, v)], v = (q⁺ − q)/h (Marsden & West 2001
// §3.4–3.5; GNI §VII.1.4), with the same two half kicks of F and the same velocity projection
// in the M(q⁺)⁻¹ metric, solved for (v, Λ) at once by dense Newton
// (integrators/general_constrained_step.hpp). On a constant mass it reduces to the equations
// above; the separable path below is kept as it is, bit for bit.
class Rattle final : public Integrator {
 public:
  Rattle(double tol, long max_iter, bool velocity_projection)
      : tol_(tol), max_iter_(max_iter), velocity_projection_(velocity_projection) {}

  MethodInfo info() const override {
    // Without the projection the momentum has an O(h) normal component: first order in (q, p),
    // and the map leaves the cotangent bundle, so neither symplectic nor symmetric.
    const unsigned geometric = kSymplectic | kSymmetric | kVariational;
    return {"rattle", velocity_projection_ ? 2 : 1,
            kExplicit | kConstrained | kConstraintsOnly | kRheonomic | kGeneralLagrangian |
                (velocity_projection_ ? geometric : 0u),
            "RATTLE (Andersen 1983), GNI §VII.1.4; docs/METHOD.md §3"};
  }

  // Explicit in the force field (one gradient per step, no Hessian of V); its nonlinear solve is
  // over the m multipliers only.
  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::limit(2.0);  // Störmer–Verlet in the tangent coordinates of a
                                             // linear oscillation about an equilibrium (GNI §I.5)
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    constraint_impulses_.reset();
    if (problem.kind() == ProblemKind::kLagrangian) {
      // The Newton test on the momentum equation and the position test share `tol`.
      const GeneralConstrainedScheme scheme{.nodes = {{0.0, 0.5}, {1.0, 0.5}},
                                            .forcing = Forcing{},
                                            .rattle_kicks = true,
                                            .constraint_tolerance = tol_,
                                            .velocity_projection = velocity_projection_};
      return general_constrained_step(problem, *problem.as_lagrangian(), scheme, state, h,
                                      {tol_, static_cast<int>(max_iter_)}, counters_,
                                      constraint_impulses_, "rattle");
    }
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    eval_total_force(problem, state.q, inverse_mass.cwiseProduct(state.p), state.t, force_);
    Vec p_half = state.p + (h / 2) * force_;
    const Vec q_start = state.q;
    const HolonomicConstraints& constraints = constraints_of(problem);
    const bool rheonomic = constraints.time_dependent();
    const double t_next = state.t + h;
    if (rheonomic) {
      constraints.constraint_jacobian_at(state.t, q_start, G_start_);
    } else {
      constraints.constraint_jacobian(q_start, G_start_);
    }
    // M⁻¹G(q)ᵀ: the direction in which each position multiplier moves q⁺.
    const Eigen::MatrixXd direction =
        inverse_mass.asDiagonal() * Eigen::MatrixXd(G_start_).transpose();
    Vec q_next = q_start + h * inverse_mass.cwiseProduct(p_half);
    Vec Lambda = Vec::Zero(G_start_.rows());
    Vec residual;
    for (long iteration = 0;; ++iteration) {
      if (rheonomic) {
        constraints.constraint_at(t_next, q_next, residual);
        constraints.constraint_jacobian_at(t_next, q_next, G_next_);
      } else {
        constraints.constraint(q_next, residual);
        constraints.constraint_jacobian(q_next, G_next_);
      }
      if (!residual.allFinite() || !q_next.allFinite()) {
        return StepStatus::failure(
            "nan", fmt::format("rattle: non-finite constraint residual in the step from t={:.17g}",
                               state.t));
      }
      const double scale = jacobian_norm(G_next_) * q_next.lpNorm<Eigen::Infinity>();
      const double size = residual.size() > 0 ? residual.lpNorm<Eigen::Infinity>() : 0.0;
      if (size <= tol_ * scale) break;
      if (iteration == max_iter_) {
        return StepStatus::failure(
            "rattle_max_iter",
            fmt::format("rattle: position multipliers not converged in {} Newton iterations in the "
                        "step from t={:.17g} to t={:.17g}: max|g(q)| = {:.3g} > tol {:g} x {:.3g}",
                        max_iter_, state.t, state.t + h, size, tol_, scale));
      }
      const Vec delta = (Eigen::MatrixXd(G_next_) * direction).partialPivLu().solve(residual);
      Lambda += delta;
      q_next -= direction * delta;
      ++counters_.newton_iters;
      ++counters_.linear_solves;
      ++counters_.factorizations;
    }
    // p½ = M(q⁺ − q)/h with the multipliers' impulse; written from Λ so that no difference of
    // nearby positions is divided by h.
    p_half -= (1 / h) * (Eigen::MatrixXd(G_start_).transpose() * Lambda);
    ConstraintImpulses impulses{Lambda / h, Vec::Zero(Lambda.size()), h};  // start = (h/2)λ
    state.q = q_next;
    state.t += h;
    eval_total_force(problem, state.q, inverse_mass.cwiseProduct(p_half), state.t, force_);
    state.p = p_half + (h / 2) * force_;
    if (velocity_projection_) {
      // (G M⁻¹ Gᵀ) ν = G M⁻¹ p̃, p⁺ = p̃ − Gᵀν: the M⁻¹-orthogonal projection onto the tangent
      // space (ν = (h/2)μ). G M⁻¹ Gᵀ is SPD for independent constraints.
      const Eigen::MatrixXd G = Eigen::MatrixXd(G_next_);
      const Eigen::MatrixXd G_Minv = G * inverse_mass.asDiagonal();
      Vec rate = G_Minv * state.p;
      if (rheonomic) {
        Vec g_t, a_t;
        constraints.constraint_time_terms(state.t, state.q, inverse_mass.cwiseProduct(state.p), g_t,
                                          a_t);
        rate += g_t;  // G M⁻¹p⁺ + ∂g/∂t = 0 at t + h
      }
      const Vec nu = (G_Minv * G.transpose()).ldlt().solve(rate);
      state.p -= G.transpose() * nu;
      impulses.end = nu;
      ++counters_.linear_solves;
      ++counters_.factorizations;
    }
    constraint_impulses_ = std::move(impulses);
    ++counters_.steps;
    return StepStatus::success();
  }

 private:
  // ‖G‖∞, the largest absolute row sum.
  static double jacobian_norm(const SparseMatrix& G) {
    Vec row_sums = Vec::Zero(G.rows());
    for (int k = 0; k < G.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(G, k); it; ++it)
        row_sums[it.row()] += std::abs(it.value());
    }
    return row_sums.size() > 0 ? row_sums.maxCoeff() : 0.0;
  }

  double tol_;
  long max_iter_;
  bool velocity_projection_;
  Vec force_;
  SparseMatrix G_start_, G_next_;
};

}  // namespace

std::unique_ptr<Integrator> make_rattle(Params& params) {
  const double tol = params.real(
      "tol", 1e-14,
      "Newton stop for the position multipliers: max|g(q)| <= tol x |G|inf x |q|inf (relative "
      "to the state's scale)",
      Range::closed_open(std::numeric_limits<double>::epsilon(), 1));
  const long max_iter =
      params.integer("max_iter", 50, "Newton iterations per step before rattle_max_iter", 1, 1000);
  const bool velocity_projection = params.flag("velocity_projection", true,
                                               "project p onto the tangent space (RATTLE); false "
                                               "keeps SHAKE's velocities (negative control)");
  return std::make_unique<Rattle>(tol, max_iter, velocity_projection);
}

}  // namespace geomint
