// Force impulses of the forced variational integrators (see forcing.hpp; docs/METHOD.md §2).
#include "integrators/forcing.hpp"

#include "integrators/newton.hpp"

namespace geomint {

Forcing read_forcing(Params& params) {
  Forcing forcing;
  const std::string slot =
      params.choice("force_slot", "split", {"minus", "plus", "split"},
                    "where the step's force impulse h F goes: F_d- (at q_k), F_d+ (at q_k+1), half "
                    "each");
  forcing.slot = slot == "minus"  ? ForceSlot::kMinus
                 : slot == "plus" ? ForceSlot::kPlus
                                  : ForceSlot::kSplit;
  const std::string at =
      params.choice("force_at", "midpoint", {"node", "midpoint"},
                    "evaluate each impulse's force at its own node, or at q_k+1/2 for all slots");
  forcing.at = at == "node" ? ForceAt::kNode : ForceAt::kMidpoint;
  return forcing;
}

void minus_impulse(const Problem& problem, const Forcing& forcing, const ImpulseStep& step,
                   const Vec& v, Vec& impulse, Counters& counters) {
  ++counters.force_evals;
  if (forcing.at == ForceAt::kNode) {
    force_of(problem).force(step.q0, v, step.t0, impulse);
  } else {
    force_of(problem).force(step.q0 + (step.h / 2) * v, v, step.t0 + step.h / 2, impulse);
  }
  impulse *= step.minus_weight * step.h;
}

void add_minus_impulse_jacobian(const Problem& problem, const Forcing& forcing,
                                const ImpulseStep& step, const Vec& v, SparseMatrix& jacobian,
                                SparseMatrix& damping, Counters& counters) {
  const bool node = forcing.at == ForceAt::kNode;
  const double h = step.h;
  if (problem.has(kForceJacobian)) {
    force_of(problem).force_jacobian_v(node ? step.q0 : Vec(step.q0 + (h / 2) * v), v,
                                       node ? step.t0 : step.t0 + h / 2, damping);
    jacobian += (step.minus_weight * h) * damping;
    return;
  }
  jacobian -= central_difference_jacobian(
      [&](const Vec& x, Vec& impulse) {
        force_of(problem).force(node ? step.q0 : Vec(step.q0 + (h / 2) * x), x,
                                node ? step.t0 : step.t0 + h / 2, impulse);
        impulse *= step.minus_weight * h;
      },
      v);
  counters.force_evals += 2 * v.size();
}

void add_plus_impulse(const Problem& problem, const Forcing& forcing, const State& start,
                      const Vec& q1, double h, const Vec& v, double plus_weight, Vec& p1,
                      Vec& force, Counters& counters) {
  const bool node = forcing.at == ForceAt::kNode;
  ++counters.force_evals;
  force_of(problem).force(node ? q1 : Vec(start.q + (h / 2) * v), v,
                          node ? start.t + h : start.t + h / 2, force);
  p1 += (plus_weight * h) * force;
}

void decide_damping_symmetry(const Problem& problem, const Vec& q, const Vec& v, double t,
                             SparseMatrix& damping, std::optional<bool>& symmetric) {
  if (symmetric || !problem.has(kForceJacobian)) return;
  force_of(problem).force_jacobian_v(q, v, t, damping);
  symmetric = (damping - SparseMatrix(damping.transpose())).norm() == 0.0;
}

}  // namespace geomint
