// Implicit partitioned Runge–Kutta step (see partitioned_rk.hpp); stage equations after GNI
// §II.2.2 and §VIII.6 (Newton on the stage values with the exact Jacobian).
#include "integrators/partitioned_rk.hpp"

#include <Eigen/Core>
#include <cmath>
#include <vector>

#include "integrators/general_step.hpp"
#include "integrators/newton.hpp"
#include "integrators/step_implementation.hpp"
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
//
// On the general kind L = ½vᵀM(q)v + a(q)ᵀv − V(q) the same unknowns and the same solve: the
// PRK on Hamilton's equations (GNI §II.2.2, Q_i = q₀ + hΣ_j a_ij v(Q_j, P_j),
// P_i = p₀ + hΣ_j â_ij L_q(Q_j, v_j)) with V_j = v(Q_j, P_j), so P_i = L_v(Q_i, V_i) and
//   R_i(V) = L_v(Q_i, V_i) − p₀ − hΣ_j â_ij [L_q(Q_j, V_j) + F_j] = 0,
//   ∂R_i/∂V_k = M(Q_i)δ_ik + h a_ik L_vq(Q_i) − h â_ik L_qv(Q_k) − h²Σ_j â_ij a_jk L_qq(Q_j)
// (on the separable kind L_v = MV, L_q = −∇V, L_vq = 0: the equations above), and the same
// update p₁ = p₀ + hΣ_j b_j [L_q + F]_j, which keeps a cyclic momentum (L_q ≡ 0) exact.
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

  // The one step of both kinds (integrators/step_implementation.hpp): they differ only in the
  // view asked at the stages — L_v = M V_i, L_q = −∇V and ∇²V on the separable kind (the
  // constant diagonal read once), the problem's LagrangianSystem on the general one.
  StepStatus step(const Problem& problem, State& state, double h) override {
    mark_step_implementation();
    const int n = problem.dof();
    const LagrangianSystem* general = problem.as_lagrangian();
    const MassOperator mass_operator(problem);
    const Vec* mass = general != nullptr ? nullptr : &mass_operator.constant_diagonal();
    const bool forced = problem.has(kForce);
    const Vec q0 = state.q;
    const Vec p0 = state.p;
    const double t0 = state.t;
    stage_q_.resize(stages_);
    stage_f_.resize(stages_);
    hessians_.resize(stages_);
    dampings_.resize(stages_);
    if (general != nullptr) {
      stage_mass_.resize(stages_);
      stage_l_vq_.resize(stages_);
      stage_l_qq_.resize(stages_);
    }

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
        stage_force(problem, general, stage_q_[j], v.segment(j * n, n), t0 + c_[j] * h,
                    stage_f_[j]);
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
        if (general != nullptr) {
          block = general->momentum(stage_q_[i], v.segment(i * n, n)) - p0;
        } else {
          block = mass->cwiseProduct(v.segment(i * n, n)) - p0;
        }
        for (int j = 0; j < stages_; ++j) {
          if (a_hat_(i, j) != 0.0) block -= (h * a_hat_(i, j)) * stage_f_[j];
        }
      }
    };
    system.jacobian = [&](const Vec& v, SparseMatrix& jacobian) {
      if (general != nullptr) {
        general_jacobian(*general, q0, v, h, jacobian, inner_scale);
        if (forced) add_general_damping(problem, q0, v, t0, h, jacobian);
        return;
      }
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
        for (int d = 0; d < n; ++d) triplets.emplace_back(i * n + d, i * n + d, (*mass)[d]);
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
    // velocities V_i = M⁻¹(p₀ + c_i h f(q₀, v₀, t₀)) (v(q₀, p₀ + c_i h f) on the general kind).
    Vec force0;
    const Vec v0 = general != nullptr ? general->velocity(q0, p0) : mass_operator.solve(q0, p0);
    stage_force(problem, general, q0, v0, t0, force0);
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
      } else if (general != nullptr) {
        v.segment(i * n, n) = general->velocity(q0, p0 + (c_[i] * h) * force0);
      } else {
        v.segment(i * n, n) = mass_operator.solve(q0, p0 + (c_[i] * h) * force0);
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
  // The stage's generalized force: −∇V(Q) + F(Q, V, t) on the separable kind,
  // L_q(Q, V) + F(Q, V, t) on the general one.
  void stage_force(const Problem& problem, const LagrangianSystem* general, const Vec& q,
                   const Vec& v, double t, Vec& force) {
    if (general == nullptr) {
      eval_total_force(problem, q, v, t, force);
      return;
    }
    ++counters_.force_evals;
    general->lagrangian_q(q, v, force);
    if (problem.has(kForce)) {
      eval_force(problem, q, v, t, force_);
      force += force_;
    }
  }

  // ∂R/∂V on the general kind (the comment above the class), every entry of every block stored
  // (zeros included: one sparsity pattern per run); `inner_scale` gets hΣ_j |L_qq(Q_j)||Q_j|.
  void general_jacobian(const LagrangianSystem& general, const Vec& q0, const Vec& v, double h,
                        SparseMatrix& jacobian, double& inner_scale) {
    const int n = static_cast<int>(q0.size());
    inner_scale = 0.0;
    for (int j = 0; j < stages_; ++j) {
      Vec qj = q0;
      for (int k = 0; k < stages_; ++k) {
        if (a_(j, k) != 0.0) qj += (h * a_(j, k)) * v.segment(k * n, n);
      }
      const Vec vj = v.segment(j * n, n);
      general.mass_matrix(qj, stage_mass_[j]);
      general.lagrangian_vq(qj, vj, stage_l_vq_[j]);
      general.lagrangian_qq(qj, vj, stage_l_qq_[j]);
      inner_scale += std::abs(h) * robust_norm((stage_l_qq_[j].cwiseAbs() * qj.cwiseAbs()).eval());
    }
    std::vector<Eigen::Triplet<double>> triplets;
    triplets.reserve(static_cast<size_t>(stages_ * stages_ * n * n));
    Eigen::MatrixXd block(n, n);
    for (int i = 0; i < stages_; ++i) {
      for (int k = 0; k < stages_; ++k) {
        block.setZero();
        if (i == k) block += stage_mass_[i];
        block += (h * a_(i, k)) * stage_l_vq_[i];
        block -= (h * a_hat_(i, k)) * stage_l_vq_[k].transpose();
        for (int j = 0; j < stages_; ++j) {
          block -= (h * h * a_hat_(i, j) * a_(j, k)) * stage_l_qq_[j];
        }
        for (int col = 0; col < n; ++col) {
          for (int row = 0; row < n; ++row) {
            triplets.emplace_back(i * n + row, k * n + col, block(row, col));
          }
        }
      }
    }
    jacobian.resize(stages_ * n, stages_ * n);
    jacobian.setFromTriplets(triplets.begin(), triplets.end());
  }

  // h â_ik C(Q_k, V_k) on the general kind (C = −∂F/∂v), added to the matrix above.
  void add_general_damping(const Problem& problem, const Vec& q0, const Vec& v, double t0, double h,
                           SparseMatrix& jacobian) {
    const int n = static_cast<int>(q0.size());
    std::vector<Eigen::Triplet<double>> triplets;
    for (int k = 0; k < stages_; ++k) {
      Vec qk = q0;
      for (int m = 0; m < stages_; ++m) {
        if (a_(k, m) != 0.0) qk += (h * a_(k, m)) * v.segment(m * n, n);
      }
      damping_at(problem, qk, v.segment(k * n, n), t0 + c_[k] * h, dampings_[k]);
      for (int i = 0; i < stages_; ++i) {
        if (a_hat_(i, k) != 0.0) add_block(triplets, i, k, n, h * a_hat_(i, k), dampings_[k]);
      }
    }
    SparseMatrix damping(stages_ * n, stages_ * n);
    damping.setFromTriplets(triplets.begin(), triplets.end());
    jacobian += damping;
  }

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
  std::vector<Eigen::MatrixXd> stage_mass_, stage_l_vq_, stage_l_qq_;  // the general kind's
  Vec force_;
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
