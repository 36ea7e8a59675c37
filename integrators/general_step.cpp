// DEL α-rule and implicit midpoint steps on the general Lagrangian kind (docs/MECHANICS_GENERAL.md
// §2–3; ../shared/MECHANICS.md §2). The step Jacobians are not symmetric (α L_vq − (1−α) L_qv),
// so each step's equation goes to dense_newton (integrators/dense_newton.hpp: Eigen's
// PartialPivLU, these problems have a few dof); this file supplies R, J and the stopping test.
#include "integrators/general_step.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "integrators/dense_newton.hpp"
#include "integrators/newton.hpp"

namespace geomint {
namespace {

bool finite(const Vec& x) { return x.allFinite(); }

double inf_norm(const Vec& x) { return dense_inf_norm(x); }

}  // namespace

std::string spec_on(const Integrator& method, const Problem& problem) {
  if (problem.kind() == ProblemKind::kLagrangian) {
    if (const auto* resolves = dynamic_cast<const ResolvesOnGeneralLagrangian*>(&method)) {
      return resolves->general_lagrangian_spec();
    }
  }
  return method.spec();
}

double GeneralVelocityJacobian::assemble(const LagrangianSystem& system, const Vec& q_bar,
                                         const Vec& v, double h, double alpha,
                                         SparseMatrix& jacobian) {
  system.mass_matrix(q_bar, dense_);
  system.lagrangian_vq(q_bar, v, lagrangian_vq_);
  system.lagrangian_qq(q_bar, v, lagrangian_qq_);
  dense_ += (h * alpha) * lagrangian_vq_ - (h * (1 - alpha)) * lagrangian_vq_.transpose() -
            (h * h * alpha * (1 - alpha)) * lagrangian_qq_;
  const Eigen::Index n = dense_.rows();
  triplets_.clear();
  triplets_.reserve(static_cast<size_t>(n * n));
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) triplets_.emplace_back(i, j, dense_(i, j));
  }
  jacobian.resize(n, n);
  jacobian.setFromTriplets(triplets_.begin(), triplets_.end());
  return std::abs(h * (1 - alpha)) *
         robust_norm((lagrangian_qq_.cwiseAbs() * q_bar.cwiseAbs()).eval());
}

StepStatus general_del_step(const LagrangianSystem& system, State& state, double h, double alpha,
                            const GeneralNewtonSettings& newton, Counters& counters) {
  const Vec q0 = state.q;
  const Vec p0 = state.p;
  Vec v = system.velocity(q0, p0);
  Vec L_q;
  DenseMatrix M, L_vq, L_qq;
  double scale = 0;  // the size of R's terms at the last evaluated v
  DenseNewtonSystem equation;
  // R(v) = L_v(q̄, v) − h(1−α)L_q(q̄, v) − p₀ at q̄ = q₀ + αh v.
  equation.residual = [&](const Vec& velocity, Vec& residual) {
    const Vec q_bar = q0 + (alpha * h) * velocity;
    system.lagrangian_q(q_bar, velocity, L_q);
    ++counters.force_evals;
    const Vec p_bar = system.momentum(q_bar, velocity);
    residual = p_bar - (h * (1 - alpha)) * L_q - p0;
    scale = inf_norm(p_bar) + std::abs(h) * inf_norm(L_q) + inf_norm(p0);
  };
  equation.converged = [&](const Vec& residual, double floor) {
    return inf_norm(residual) <= floor * scale;
  };
  // ∂R/∂v = L_vv + hα L_vq − h(1−α) L_qv − h²α(1−α) L_qq (h times ∂R/∂q₁ of MECHANICS.md §2).
  equation.jacobian = [&](const Vec& velocity, DenseMatrix& jacobian) {
    const Vec q_bar = q0 + (alpha * h) * velocity;
    system.mass_matrix(q_bar, M);
    system.lagrangian_vq(q_bar, velocity, L_vq);
    system.lagrangian_qq(q_bar, velocity, L_qq);
    jacobian = M + (h * alpha) * L_vq - (h * (1 - alpha)) * L_vq.transpose() -
               (h * h * alpha * (1 - alpha)) * L_qq;
  };
  // The momentum maps of a variational step are exact only for the exact solve (discrete
  // Noether), so p_φ wants the residual at its round-off floor (the polish), and L_q below must
  // be that of the accepted v.
  equation.reevaluate_after_rejected_polish = true;
  equation.method = "general del";
  const StepStatus status = dense_newton(equation, v, newton, counters);
  if (!status.ok) return status;
  const Vec q_bar = q0 + (alpha * h) * v;
  state.p = system.momentum(q_bar, v) + (h * alpha) * L_q;  // L_q is at the accepted v
  state.q = q0 + h * v;
  state.t += h;
  ++counters.steps;
  if (!finite(state.q) || !finite(state.p)) {
    return StepStatus::failure("nan", "general del: non-finite state");
  }
  return StepStatus::success();
}

StepStatus general_implicit_midpoint_step(const LagrangianSystem& system, State& state, double h,
                                          const GeneralNewtonSettings& newton, Counters& counters) {
  const long n = state.q.size();
  Vec z0(2 * n);
  z0 << state.q, state.p;
  Vec z = z0;  // the midpoint z̄, started at z₀
  Vec f(2 * n), L_q;
  // R(z̄) = z̄ − z₀ − (h/2) f(z̄), block-wise scales for the q and p rows (different units).
  double q_scale = 0, p_scale = 0;
  DenseNewtonSystem equation;
  equation.residual = [&](const Vec& midpoint, Vec& residual) {
    const Vec q = midpoint.head(n);
    const Vec v = system.velocity(q, midpoint.tail(n));
    system.lagrangian_q(q, v, L_q);
    ++counters.force_evals;
    f << v, L_q;
    residual = midpoint - z0 - (h / 2) * f;
    q_scale = inf_norm(z0.head(n)) + std::abs(h) * inf_norm(v);
    p_scale = inf_norm(z0.tail(n)) + std::abs(h) * inf_norm(L_q);
  };
  equation.converged = [&](const Vec& residual, double floor) {
    return inf_norm(residual.head(n)) <= floor * q_scale &&
           inf_norm(residual.tail(n)) <= floor * p_scale;
  };
  DenseMatrix field_jacobian;
  equation.jacobian = [&](const Vec& midpoint, DenseMatrix& jacobian) {
    system.hamiltonian_vector_field_jacobian(midpoint.head(n), midpoint.tail(n), field_jacobian);
    jacobian = DenseMatrix::Identity(2 * n, 2 * n) - (h / 2) * field_jacobian;
  };
  equation.method = "general implicit midpoint";
  const StepStatus status = dense_newton(equation, z, newton, counters);
  if (!status.ok) return status;
  const Vec z1 = 2 * z - z0;
  state.q = z1.head(n);
  state.p = z1.tail(n);
  state.t += h;
  ++counters.steps;
  if (!finite(z1)) return StepStatus::failure("nan", "general implicit midpoint: non-finite state");
  return StepStatus::success();
}

StepStatus general_partitioned_rk_step(const LagrangianSystem& system, State& state, double h,
                                       const DenseMatrix& a, const DenseMatrix& a_hat, const Vec& b,
                                       const GeneralNewtonSettings& newton, Counters& counters) {
  const long n = state.q.size();
  const long s = b.size();
  const Vec q0 = state.q;
  const Vec p0 = state.p;
  // Stage i's unknowns are z.segment(2ni, 2n) = (Q_i, P_i), all started at (q₀, p₀).
  Vec z(2 * n * s);
  for (long i = 0; i < s; ++i) z.segment(2 * n * i, 2 * n) << q0, p0;
  std::vector<Vec> velocities(s), forces(s);  // v(Q_j, P_j) and L_q(Q_j, v_j)
  DenseMatrix field_jacobian;
  double q_scale = 0, p_scale = 0;
  DenseNewtonSystem equation;
  equation.residual = [&](const Vec& stages, Vec& residual) {
    double largest_v = 0, largest_force = 0;
    for (long j = 0; j < s; ++j) {
      const Vec Q = stages.segment(2 * n * j, n);
      velocities[j] = system.velocity(Q, stages.segment(2 * n * j + n, n));
      system.lagrangian_q(Q, velocities[j], forces[j]);
      ++counters.force_evals;
      largest_v = std::max(largest_v, inf_norm(velocities[j]));
      largest_force = std::max(largest_force, inf_norm(forces[j]));
    }
    residual.resize(2 * n * s);
    for (long i = 0; i < s; ++i) {
      Vec q_row = stages.segment(2 * n * i, n) - q0;
      Vec p_row = stages.segment(2 * n * i + n, n) - p0;
      for (long j = 0; j < s; ++j) {
        q_row -= (h * a(i, j)) * velocities[j];
        p_row -= (h * a_hat(i, j)) * forces[j];
      }
      residual.segment(2 * n * i, 2 * n) << q_row, p_row;
    }
    q_scale = inf_norm(q0) + std::abs(h) * largest_v;
    p_scale = inf_norm(p0) + std::abs(h) * largest_force;
  };
  equation.converged = [&](const Vec& residual, double floor) {
    for (long i = 0; i < s; ++i) {
      if (inf_norm(residual.segment(2 * n * i, n)) > floor * q_scale) return false;
      if (inf_norm(residual.segment(2 * n * i + n, n)) > floor * p_scale) return false;
    }
    return true;
  };
  // ∂R_i/∂(Q_j, P_j) = δ_ij I − h diag(a_ij I, â_ij I) J_j, J_j the field Jacobian at stage j.
  equation.jacobian = [&](const Vec& stages, DenseMatrix& jacobian) {
    jacobian.resize(2 * n * s, 2 * n * s);
    jacobian.setIdentity();
    for (long j = 0; j < s; ++j) {
      system.hamiltonian_vector_field_jacobian(stages.segment(2 * n * j, n),
                                               stages.segment(2 * n * j + n, n), field_jacobian);
      for (long i = 0; i < s; ++i) {
        jacobian.block(2 * n * i, 2 * n * j, n, 2 * n) -= (h * a(i, j)) * field_jacobian.topRows(n);
        jacobian.block(2 * n * i + n, 2 * n * j, n, 2 * n) -=
            (h * a_hat(i, j)) * field_jacobian.bottomRows(n);
      }
    }
  };
  // The update below reads the stage velocities and forces of the accepted z.
  equation.reevaluate_after_rejected_polish = true;
  equation.method = "general partitioned RK";
  const StepStatus status = dense_newton(equation, z, newton, counters);
  if (!status.ok) return status;
  for (long j = 0; j < s; ++j) {
    state.q += (h * b[j]) * velocities[j];
    state.p += (h * b[j]) * forces[j];
  }
  state.t += h;
  ++counters.steps;
  if (!finite(state.q) || !finite(state.p)) {
    return StepStatus::failure("nan", "general partitioned RK: non-finite state");
  }
  return StepStatus::success();
}

}  // namespace geomint
