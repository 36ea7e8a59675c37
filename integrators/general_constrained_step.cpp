// The constrained, forced DEL step on the general Lagrangian kind (general_constrained_step.hpp):
// the residual, its Jacobian and the stopping test for dense_newton, then the momentum and its
// projection onto the tangent space.
#include "integrators/general_constrained_step.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "integrators/dense_newton.hpp"
#include "problems/force.hpp"

namespace geomint {
namespace {

// g, G and the time terms at one time: the time-dependent calls for rheonomic constraints, the
// time-free ones otherwise.
struct ConstraintsAtTime {
  ConstraintsAtTime(const HolonomicConstraints& c, double time)
      : constraints(c), t(time), rheonomic(c.time_dependent()) {}
  void value(const Vec& q, Vec& g) const {
    rheonomic ? constraints.constraint_at(t, q, g) : constraints.constraint(q, g);
  }
  Eigen::MatrixXd jacobian(const Vec& q) const {
    SparseMatrix G;
    rheonomic ? constraints.constraint_jacobian_at(t, q, G) : constraints.constraint_jacobian(q, G);
    return Eigen::MatrixXd(G);
  }
  const HolonomicConstraints& constraints;
  double t;
  bool rheonomic;
};

// ‖G‖∞, the largest absolute row sum.
double row_sum_norm(const Eigen::MatrixXd& G) {
  return G.rows() > 0 ? G.cwiseAbs().rowwise().sum().maxCoeff() : 0.0;
}

}  // namespace

StepStatus general_constrained_step(const Problem& problem, const LagrangianSystem& system,
                                    const GeneralConstrainedScheme& scheme, State& state, double h,
                                    const GeneralNewtonSettings& newton, Counters& counters,
                                    std::optional<ConstraintImpulses>& impulses,
                                    const char* method) {
  const HolonomicConstraints& constraints = constraints_of(problem);
  const long n = state.q.size();
  const long m = constraints.constraint_count();
  const Vec q0 = state.q;
  const Vec p0 = state.p;
  const double t0 = state.t;
  const ConstraintsAtTime start(constraints, t0), end(constraints, t0 + h);
  const Eigen::MatrixXd G0 = start.jacobian(q0);
  const Eigen::MatrixXd G0_transpose = G0.transpose();
  DenseMatrix M, L_vq, L_qq;
  system.mass_matrix(q0, M);
  // ρ turns g/h (a velocity) into the units of R₁ (a momentum), so that dense_newton's ‖R‖∞
  // (its polishing test) weighs both blocks alike.
  const double rho = M.diagonal().maxCoeff();

  // The impulses of the force (none on an unforced problem).
  const bool forced = problem.has(kForce);
  const double minus = forced && !scheme.rattle_kicks ? scheme.forcing.minus_weight() : 0.0;
  const double plus = forced && !scheme.rattle_kicks ? scheme.forcing.plus_weight() : 0.0;
  const ImpulseStep impulse_step{q0, t0, h, minus};
  Vec start_kick = Vec::Zero(n);  // RATTLE's explicit F_d⁻
  if (forced && scheme.rattle_kicks) {
    ++counters.force_evals;
    force_of(problem).force(q0, system.velocity(q0, p0), t0, start_kick);
    start_kick *= h / 2;
  }

  // x = (v, Λ); the residual callback keeps what the stopping test and p₁ need.
  Vec x(n + m);
  x.head(n) = system.velocity(q0, p0);
  x.tail(m).setZero();
  Vec L_q, p_node, impulse, g;
  double scale = 0, g_norm = 0, g_threshold = 0;
  DenseNewtonSystem equation;
  equation.residual = [&](const Vec& unknowns, Vec& residual) {
    const Vec v = unknowns.head(n);
    residual.resize(n + m);
    Vec R1 = -p0 - start_kick;
    scale = dense_inf_norm(p0) + dense_inf_norm(start_kick);
    for (const QuadratureNode& node : scheme.nodes) {
      const Vec q_node = q0 + (node.a * h) * v;
      system.lagrangian_q(q_node, v, L_q);
      ++counters.force_evals;
      p_node = system.momentum(q_node, v);
      R1 += node.w * (p_node - (h * (1 - node.a)) * L_q);
      scale += std::abs(node.w) * (dense_inf_norm(p_node) + std::abs(h) * dense_inf_norm(L_q));
    }
    if (minus > 0.0) {
      minus_impulse(problem, scheme.forcing, impulse_step, v, impulse, counters);
      R1 -= impulse;
      scale += dense_inf_norm(impulse);
    }
    const Vec multiplier_force = G0_transpose * unknowns.tail(m);
    R1 += multiplier_force;
    scale += dense_inf_norm(multiplier_force);
    const Vec q1 = q0 + h * v;
    end.value(q1, g);
    g_norm = dense_inf_norm(g);
    g_threshold = scheme.constraint_tolerance * row_sum_norm(end.jacobian(q1)) * dense_inf_norm(q1);
    residual << R1, (rho / h) * g;
  };
  equation.converged = [&](const Vec& residual, double floor) {
    return dense_inf_norm(residual.head(n)) <= floor * scale && g_norm <= g_threshold;
  };
  // [Σ_j w_j(M_j + h a_j L_vq,j − h(1−a_j) L_vq,jᵀ − h²a_j(1−a_j) L_qq,j) + w⁻hC,  G₀ᵀ;
  //  ρ G(q₁),  0].
  SparseMatrix minus_jacobian, damping;
  equation.jacobian = [&](const Vec& unknowns, DenseMatrix& jacobian) {
    const Vec v = unknowns.head(n);
    jacobian = DenseMatrix::Zero(n + m, n + m);
    for (const QuadratureNode& node : scheme.nodes) {
      const Vec q_node = q0 + (node.a * h) * v;
      system.mass_matrix(q_node, M);
      system.lagrangian_vq(q_node, v, L_vq);
      system.lagrangian_qq(q_node, v, L_qq);
      jacobian.topLeftCorner(n, n) +=
          node.w * (M + (h * node.a) * L_vq - (h * (1 - node.a)) * L_vq.transpose() -
                    (h * h * node.a * (1 - node.a)) * L_qq);
    }
    if (minus > 0.0) {
      minus_jacobian.resize(n, n);
      minus_jacobian.setZero();
      add_minus_impulse_jacobian(problem, scheme.forcing, impulse_step, v, minus_jacobian, damping,
                                 counters);
      jacobian.topLeftCorner(n, n) += DenseMatrix(minus_jacobian);
    }
    jacobian.topRightCorner(n, m) = G0_transpose;
    jacobian.bottomLeftCorner(m, n) = rho * end.jacobian(q0 + h * v);
  };
  equation.method = method;
  const StepStatus status = dense_newton(equation, x, newton, counters);
  if (!status.ok) return status;

  // p₁ = Σ_j w_j [L_v(q^j, v) + h a_j L_q(q^j, v)] + F_d⁺ at the accepted v.
  const Vec v = x.head(n);
  const Vec q1 = q0 + h * v;
  Vec p1 = Vec::Zero(n);
  for (const QuadratureNode& node : scheme.nodes) {
    const Vec q_node = q0 + (node.a * h) * v;
    system.lagrangian_q(q_node, v, L_q);
    ++counters.force_evals;
    p1 += node.w * (system.momentum(q_node, v) + (h * node.a) * L_q);
  }
  Vec force;
  if (forced && scheme.rattle_kicks) {
    ++counters.force_evals;
    force_of(problem).force(q1, v, t0 + h, force);
    p1 += (h / 2) * force;
  } else if (plus > 0.0) {
    add_plus_impulse(problem, scheme.forcing, state, q1, h, v, plus, p1, force, counters);
  }
  ConstraintImpulses out{x.tail(m), Vec::Zero(m), h};
  if (scheme.velocity_projection) {
    // (G M⁻¹Gᵀ)ν = G M⁻¹(p₁ − a) + g_t, p₁ ← p₁ − Gᵀν: the M(q₁)⁻¹-orthogonal projection onto
    // the tangent space, each M⁻¹ a solve of the system's own (solve_mass).
    const Eigen::MatrixXd G1 = end.jacobian(q1);
    Eigen::MatrixXd inverse_mass_G1_transpose(n, m);
    Vec column;
    for (long k = 0; k < m; ++k) {
      system.solve_mass(q1, G1.row(k).transpose(), column);
      inverse_mass_G1_transpose.col(k) = column;
    }
    Vec rate = G1 * system.velocity(q1, p1);
    if (end.rheonomic) {
      Vec g_t, a_t;
      constraints.constraint_time_terms(t0 + h, q1, system.velocity(q1, p1), g_t, a_t);
      rate += g_t;
    }
    const Vec nu = (G1 * inverse_mass_G1_transpose).ldlt().solve(rate);
    p1 -= G1.transpose() * nu;
    out.end = nu;
    ++counters.linear_solves;
    ++counters.factorizations;
  }
  if (!q1.allFinite() || !p1.allFinite()) {
    return StepStatus::failure(
        "nan", fmt::format("{}: non-finite state in the step from t={:.17g}", method, t0));
  }
  state.q = q1;
  state.p = p1;
  state.t = t0 + h;
  impulses = std::move(out);
  ++counters.steps;
  return StepStatus::success();
}

}  // namespace geomint
