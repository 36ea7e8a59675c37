// Steps of the variational and Hamiltonian-side schemes on the general Lagrangian kind
// L = ½vᵀM(q)v + a(q)ᵀv − V(q) (docs/MECHANICS_GENERAL.md §2–3; Marsden & West 2001 §2.1, §2.6):
// dense Newton on the non-symmetric step Jacobian with a partially pivoted LU.
#pragma once

#include <string>
#include <vector>

#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"

namespace geomint {

// MethodInfo::flags bit kGeneralLagrangian (integrator.hpp): without it a method assumes the
// separable constant-mass form (its step uses M⁻¹p and ∇V: Verlet, symplectic Euler, Newmark,
// RATTLE, hp's minimisation form), and applicable() refuses it on is_non_separable problems.

// A method without kGeneralLagrangian that knows a more specific reason than "assumes a separable
// Lagrangian" for refusing a non-separable problem derives from this too (hp:solver=minimize: its
// general step has no scalar objective); applicable() reports the reason when it is not empty.
class ExplainsGeneralRefusal {
 public:
  virtual ~ExplainsGeneralRefusal() = default;
  virtual std::string general_lagrangian_refusal() const = 0;
};

// A method whose options resolve differently on a non-separable problem derives from this too:
// `hp` without solver= runs the Newton step there (its minimiser has no objective), so a row must
// name hp:…,solver=newton, not the separable default solver=minimize that its spec() reads —
// otherwise re-running the row's spec is refused. Returns the canonical spec of what runs.
class ResolvesOnGeneralLagrangian {
 public:
  virtual ~ResolvesOnGeneralLagrangian() = default;
  virtual std::string general_lagrangian_spec() const = 0;
};

// The canonical spec of what `method` runs on `problem`, the one a result row records: spec(),
// or on a non-separable problem the ResolvesOnGeneralLagrangian spec where the method has one.
std::string spec_on(const Integrator& method, const Problem& problem);

// The registry's test specs flagged kGeneralLagrangian (for refusal messages and tests).
std::vector<std::string> general_lagrangian_methods();

struct GeneralNewtonSettings {
  double tolerance = 1e-12;  // relative to the terms each residual balances
  int max_iterations = 50;
};

// ∂R/∂v of the velocity equation that del and hp solve on every kind at one node α,
//   R(v) = L_v(q̄, v) − p₀ − h(1−α)L_q(q̄, v) (− F_d⁻),   q̄ = q₀ + αhv,
// on the general kind: M(q̄) + hα L_vq − h(1−α) L_qv − h²α(1−α) L_qq (not symmetric unless L_vq
// is). Stored with every entry, zeros included, so that NewtonSolver keeps one sparsity pattern
// per run; the dense blocks are kept between calls.
class GeneralVelocityJacobian {
 public:
  // Assembles the matrix at (q̄, v) into `jacobian` and returns the size of the terms inside the
  // residual's L_q part, |h(1−α)|·‖|L_qq||q̄|‖ (NewtonSystem::inner_term_scale).
  double assemble(const LagrangianSystem& system, const Vec& q_bar, const Vec& v, double h,
                  double alpha, SparseMatrix& jacobian);

 private:
  DenseMatrix dense_, lagrangian_vq_, lagrangian_qq_;
  std::vector<Eigen::Triplet<double>> triplets_;
};

// The α-rule DEL step, L_d = h L((1−α)q₀ + αq₁, (q₁ − q₀)/h), in position–momentum form:
//   solve  L_v(q̄, v̄) − h(1−α) L_q(q̄, v̄) = p₀   for v̄ = (q₁ − q₀)/h,
//   then   p₁ = L_v(q̄, v̄) + hα L_q(q̄, v̄).
// Counts force evaluations (one per L_q), Newton iterations and linear solves in `counters`.
StepStatus general_del_step(const LagrangianSystem& system, State& state, double h, double alpha,
                            const GeneralNewtonSettings& newton, Counters& counters);

// The implicit midpoint rule on the Hamiltonian view, z = (q, p), z₁ = z₀ + h f((z₀ + z₁)/2),
// f = (v(q, p), L_q(q, v(q, p))) (symplectic for any H).
StepStatus general_implicit_midpoint_step(const LagrangianSystem& system, State& state, double h,
                                          const GeneralNewtonSettings& newton, Counters& counters);

// The generalized leapfrog on the Hamiltonian view (GNI §VI.3, (3.4)–(3.6)),
// integrators/generalized_leapfrog.cpp: p½ = p₀ − (h/2)H_q(q₀, p½), q₁ = q₀ + (h/2)[H_p(q₀, p½) +
// H_p(q₁, p½)], p₁ = p½ − (h/2)H_q(q₁, p½), each implicit equation by dense Newton.
StepStatus general_leapfrog_step(const LagrangianSystem& system, State& state, double h,
                                 const GeneralNewtonSettings& newton, Counters& counters);

// A partitioned Runge–Kutta method on the Hamiltonian view, q̇ = H_p = v(q, p),
// ṗ = −H_q = L_q(q, v(q, p)) (GNI §II.2.2): Q_i = q₀ + hΣ_j a_ij v(Q_j, P_j),
// P_i = p₀ + hΣ_j â_ij L_q(Q_j, v_j), q₁ = q₀ + hΣ b_j v_j, p₁ = p₀ + hΣ b_j L_q,j. Newton on all
// stage values (Q, P) at once with the dense LU of I − h(A ⊗ field Jacobian); Gauss (â = a) and
// Lobatto IIIA–IIIB are symplectic for any H. `a`, `a_hat` are s × s, `b` has s entries.
StepStatus general_partitioned_rk_step(const LagrangianSystem& system, State& state, double h,
                                       const DenseMatrix& a, const DenseMatrix& a_hat, const Vec& b,
                                       const GeneralNewtonSettings& newton, Counters& counters);

}  // namespace geomint
