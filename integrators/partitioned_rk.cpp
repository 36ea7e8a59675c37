// Implicit partitioned Runge–Kutta step (see partitioned_rk.hpp); stage equations after GNI
// §II.2.2 and §VIII.6 (Newton on the stage values with the exact Jacobian).
#include "integrators/partitioned_rk.hpp"

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "integrators/general_step.hpp"
#include "integrators/newton.hpp"
#include "integrators/tangent.hpp"
#include "problems/mass_operator.hpp"

namespace geomint {
namespace {

// Steps whose sizes agree to this relative tolerance continue each other (warm start below).
constexpr double kSameStep = 1e-6;

// Unknowns: the stage velocities V = (V_1, …, V_s) (s·n values). With Q_j(V) = q₀ + hΣ_k a_jk V_k
// and the stage forces F_j = −∇V(Q_j) + F(Q_j, V_j, t₀ + c_j h), the stage equations are
//   R_i(V) = M V_i − p₀ − hΣ_j â_ij F_j = 0,
//   ∂R_i/∂V_k = M δ_ik + h²Σ_j â_ij a_jk ∇²V(Q_j) + h â_ik C(Q_k, V_k)   (C = −∂F/∂v),
// residual in momentum units as in implicit_midpoint. The ∂F/∂q part of a force is left out of
// the Jacobian (as in implicit_euler and implicit_midpoint); without force_jacobian_v the
// velocity part is differenced. Eliminating P keeps one unknown per stage and degree of freedom
// whatever the force; for s = 1 Gauss this is exactly implicit_midpoint's residual.
//
// p₁ = p₀ + hΣ_j b_j F_j and pairwise forces sum to zero at any stage positions, so linear
// momentum is exact whatever the convergence; angular momentum (a quadratic invariant, GNI
// §IV.2) needs the converged solve, hence the polishing correction.
class ImplicitPartitionedRk final : public Integrator {
 public:
  ImplicitPartitionedRk(const coefficients::PartitionedTableau& tableau, MethodInfo info,
                        const NewtonOptions& newton)
      : stages_(tableau.stages), info_(std::move(info)), newton_(newton) {
    a_.resize(stages_, stages_);
    a_hat_.resize(stages_, stages_);
    b_.resize(stages_);
    c_.resize(stages_);
    for (int i = 0; i < stages_; ++i) {
      b_[i] = static_cast<double>(tableau.b[i]);
      c_[i] = static_cast<double>(tableau.c[i]);
      for (int j = 0; j < stages_; ++j) {
        a_(i, j) = static_cast<double>(tableau.a[i][j]);
        a_hat_(i, j) = static_cast<double>(tableau.a_hat[i][j]);
      }
    }
    // Lagrange interpolation through the nodes c_j, evaluated at 1 + c_i (the next step's nodes).
    extrapolation_.resize(stages_, stages_);
    for (int i = 0; i < stages_; ++i) {
      for (int j = 0; j < stages_; ++j) {
        double weight = 1.0;
        for (int m = 0; m < stages_; ++m) {
          if (m != j) weight *= (1.0 + c_[i] - c_[m]) / (c_[j] - c_[m]);
        }
        extrapolation_(i, j) = weight;
      }
    }
    newton_.options().polish = true;  // quadratic invariants to round-off, not to the tolerance
  }

  MethodInfo info() const override { return info_; }

  StabilityPrediction predicted_linear_stability() const override {
    return StabilityPrediction::none(
        "no formula in geomint: the partitioned Runge-Kutta tableaux' limits are not derived here");
  }

  void reset(const Problem& problem, const State& state, double h) override {
    Integrator::reset(problem, state, h);
    newton_.forget_pattern();
    previous_v_.resize(0);
  }

  StepStatus step(const Problem& problem, State& state, double h) override {
    if (problem.kind() == ProblemKind::kLagrangian) {
      // On (q, p) of the Hamiltonian view (../shared/MECHANICS.md §4).
      return general_partitioned_rk_step(
          *problem.as_lagrangian(), state, h, a_, a_hat_, b_,
          {newton_.options().tolerance, newton_.options().max_iterations}, counters_);
    }
    const int n = problem.dof();
    const Vec& mass = MassOperator(problem).constant_diagonal();
    const Vec& inverse_mass = MassOperator(problem).constant_inverse_diagonal();
    const bool forced = problem.has(kForce);
    const Vec q0 = state.q;
    const Vec p0 = state.p;
    const double t0 = state.t;
    stage_q_.resize(stages_);
    stage_f_.resize(stages_);
    hessians_.resize(stages_);
    dampings_.resize(stages_);

    // Stage positions and forces at V, memoised (the solver evaluates the residual at the
    // accepted iterate last, and the update below needs the forces there).
    bool memo_valid = false;
    Vec memo_v;
    const auto evaluate_stages = [&](const Vec& v) {
      if (memo_valid && memo_v == v) return;
      memo_valid = true;
      memo_v = v;
      for (int j = 0; j < stages_; ++j) {
        stage_q_[j] = q0;
        for (int k = 0; k < stages_; ++k) {
          if (a_(j, k) != 0.0) stage_q_[j] += (h * a_(j, k)) * v.segment(k * n, n);
        }
        eval_total_force(problem, stage_q_[j], v.segment(j * n, n), t0 + c_[j] * h, stage_f_[j]);
      }
    };

    double inner_scale = 0.0;
    NewtonSystem system;
    system.inner_term_scale = [&] { return inner_scale; };
    system.residual = [&](const Vec& v, Vec& residual) {
      evaluate_stages(v);
      residual.resize(stages_ * n);
      for (int i = 0; i < stages_; ++i) {
        auto block = residual.segment(i * n, n);
        block = mass.cwiseProduct(v.segment(i * n, n)) - p0;
        for (int j = 0; j < stages_; ++j) {
          if (a_hat_(i, j) != 0.0) block -= (h * a_hat_(i, j)) * stage_f_[j];
        }
      }
    };
    system.jacobian = [&](const Vec& v, SparseMatrix& jacobian) {
      std::vector<Eigen::Triplet<double>> triplets;
      inner_scale = 0.0;
      for (int j = 0; j < stages_; ++j) {
        Vec qj = q0;
        for (int k = 0; k < stages_; ++k) {
          if (a_(j, k) != 0.0) qj += (h * a_(j, k)) * v.segment(k * n, n);
        }
        eval_hessian(problem, qj, hessians_[j]);
        inner_scale += std::abs(h) * gradient_term_scale(hessians_[j], qj);
        if (forced) damping_at(problem, qj, v.segment(j * n, n), t0 + c_[j] * h, dampings_[j]);
      }
      for (int i = 0; i < stages_; ++i) {
        for (int d = 0; d < n; ++d) triplets.emplace_back(i * n + d, i * n + d, mass[d]);
        for (int k = 0; k < stages_; ++k) {
          // Structural zeros of the tableau stay zeros: the pattern is the same every step.
          for (int j = 0; j < stages_; ++j) {
            const double weight = h * h * a_hat_(i, j) * a_(j, k);
            if (weight == 0.0) continue;
            add_block(triplets, i, k, n, weight, hessians_[j]);
          }
          if (forced && a_hat_(i, k) != 0.0) {
            add_block(triplets, i, k, n, h * a_hat_(i, k), dampings_[k]);
          }
        }
      }
      jacobian.resize(stages_ * n, stages_ * n);
      jacobian.setFromTriplets(triplets.begin(), triplets.end());
    };
    system.symmetric = false;

    // Start from the previous step's stage velocities extrapolated to this step's nodes (GNI
    // §VIII.6.1) when this step continues it, otherwise from the explicit-Euler stage
    // velocities V_i = M⁻¹(p₀ + c_i h f(q₀, v₀, t₀)).
    Vec force0;
    eval_total_force(problem, q0, inverse_mass.cwiseProduct(p0), t0, force0);
    Vec v(stages_ * n);
    // The harness steps h = t_{k+1} − t_k with t_k = t_0 + k·dt, which differs from dt by
    // rounding (a relative 1e-10 at t/dt = 1e6), so h is compared with a relative tolerance; an
    // exact comparison skipped the warm start on about 60 % of the steps. The guess only has to
    // be close: Newton's answer does not depend on it.
    const bool continues = previous_v_.size() == stages_ * n &&
                           std::abs(previous_h_ - h) <= kSameStep * std::abs(h) &&
                           previous_q_ == q0 && previous_p_ == p0;
    for (int i = 0; i < stages_; ++i) {
      if (continues) {
        v.segment(i * n, n).setZero();
        for (int j = 0; j < stages_; ++j) {
          v.segment(i * n, n) += extrapolation_(i, j) * previous_v_.segment(j * n, n);
        }
      } else {
        v.segment(i * n, n) = inverse_mass.cwiseProduct(p0 + (c_[i] * h) * force0);
      }
    }
    const double residual_scale = std::sqrt(static_cast<double>(stages_)) *
                                  (robust_norm(p0) + std::abs(h) * robust_norm(force0));
    const NewtonResult result = newton_.solve(system, v, residual_scale);
    counters_.newton_iters += result.iterations;
    counters_.linear_solves += result.linear_solves;
    counters_.factorizations += result.factorizations;
    if (!result.converged) return StepStatus::failure(result.reason, describe(result));

    evaluate_stages(v);
    for (int j = 0; j < stages_; ++j) {
      state.q += (h * b_[j]) * v.segment(j * n, n);
      state.p += (h * b_[j]) * stage_f_[j];
    }
    state.t = t0 + h;
    previous_v_ = v;
    previous_h_ = h;
    previous_q_ = state.q;
    previous_p_ = state.p;
    ++counters_.steps;
    return StepStatus::success();
  }

  // Unforced, at the converged stage velocities V with H_j = ∇²V(Q_j), the implicit function
  // theorem on R_i = M V_i − p₀ + hΣ_j â_ij ∇V(Q_j) = 0 gives
  //   Σ_k (M δ_ik + h²Σ_j â_ij a_jk H_j) δV_k = δp₀ − hΣ_j â_ij H_j δq₀,
  //   δQ_j = δq₀ + hΣ_k a_jk δV_k,  δq₁ = δq₀ + hΣ_j b_j δV_j,  δp₁ = δp₀ − hΣ_j b_j H_j δQ_j.
  bool has_step_tangent(const Problem& problem) const override { return tangent_applies(problem); }
  StepStatus step_tangent(const Problem& problem, State& state, double h,
                          Eigen::MatrixXd& tangent) override {
    const int n = problem.dof();
    const Vec q0 = state.q;
    const StepStatus status = step(problem, state, h);
    if (!status.ok) return status;
    std::vector<Eigen::MatrixXd> hessians;
    for (int j = 0; j < stages_; ++j) {
      Vec qj = q0;
      for (int k = 0; k < stages_; ++k) qj += (h * a_(j, k)) * previous_v_.segment(k * n, n);
      hessians.push_back(dense_hessian(problem, qj));
    }
    Eigen::MatrixXd matrix = Eigen::MatrixXd::Zero(stages_ * n, stages_ * n);
    Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(stages_ * n, 2 * n);
    for (int i = 0; i < stages_; ++i) {
      matrix.block(i * n, i * n, n, n) +=
          Eigen::MatrixXd(MassOperator(problem).constant_diagonal().asDiagonal());
      rhs.block(i * n, n, n, n).setIdentity();
      for (int j = 0; j < stages_; ++j) {
        rhs.block(i * n, 0, n, n) -= (h * a_hat_(i, j)) * hessians[j];
        for (int k = 0; k < stages_; ++k) {
          matrix.block(i * n, k * n, n, n) += (h * h * a_hat_(i, j) * a_(j, k)) * hessians[j];
        }
      }
    }
    const Eigen::MatrixXd dv = matrix.partialPivLu().solve(rhs);
    TangentBlock block(n);
    const TangentBlock start(n);
    for (int j = 0; j < stages_; ++j) {
      Eigen::MatrixXd dq_stage = start.q;
      for (int k = 0; k < stages_; ++k) dq_stage += (h * a_(j, k)) * dv.middleRows(k * n, n);
      block.q += (h * b_[j]) * dv.middleRows(j * n, n);
      block.p -= (h * b_[j]) * (hessians[j] * dq_stage);
    }
    tangent = block.stacked();
    return status;
  }

 private:
  // C = −∂F/∂v at a stage: the problem's force_jacobian_v, or central differences.
  void damping_at(const Problem& problem, const Vec& q, const Vec& v, double t, SparseMatrix& C) {
    if (problem.has(kForceJacobian)) {
      force_of(problem).force_jacobian_v(q, v, t, C);
      return;
    }
    C = -central_difference_jacobian([&](const Vec& y, Vec& f) { eval_force(problem, q, y, t, f); },
                                     v);
    counters_.force_evals += 2 * v.size();
  }

  static void add_block(std::vector<Eigen::Triplet<double>>& triplets, int row_block, int col_block,
                        int n, double weight, const SparseMatrix& block) {
    for (int col = 0; col < block.outerSize(); ++col) {
      for (SparseMatrix::InnerIterator it(block, col); it; ++it) {
        triplets.emplace_back(row_block * n + static_cast<int>(it.row()),
                              col_block * n + static_cast<int>(it.col()), weight * it.value());
      }
    }
  }

  int stages_;
  MethodInfo info_;
  Eigen::MatrixXd a_, a_hat_, extrapolation_;
  Vec b_, c_;
  NewtonSolver newton_;
  std::vector<Vec> stage_q_, stage_f_;
  std::vector<SparseMatrix> hessians_, dampings_;
  // Last step's stage velocities, step and end state, for the starting guess of the next one.
  Vec previous_v_, previous_q_, previous_p_;
  double previous_h_ = 0.0;
};

}  // namespace

std::unique_ptr<Integrator> make_partitioned_rk(const coefficients::PartitionedTableau& tableau,
                                                MethodInfo info, Params& params) {
  const NewtonOptions newton = read_newton_options(params, "sqrt(s)(|p| + h|f|)");
  return std::make_unique<ImplicitPartitionedRk>(tableau, std::move(info), newton);
}

}  // namespace geomint
