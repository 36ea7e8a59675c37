// Tests of the variational integrators (del, hp), Newmark and the implicit midpoint rule
// (docs/METHOD.md §1, §2, §4; Marsden & West 2001; Kane et al. 2000; Kharevych et al. 2006):
// equivalences between the forms, symplecticity of one step, discrete Noether with and without
// forcing, the energy decay under damping, the two HP solvers, failures and parameter validation.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <string>
#include <vector>

#include "integrators/general_step.hpp"
#include "integrators/integrator.hpp"
#include "integrators/newton.hpp"
#include "integrators/newton_profile.hpp"
#include "tests/test_util.hpp"
#include "verify/verify.hpp"

namespace geomint {
namespace variational_test {
namespace {

std::string test_name(const testing::TestParamInfo<std::string>& info) {
  std::string name;
  for (char c : info.param) name += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return name;
}

double relative_distance(const State& a, const State& b) {
  const double difference = std::sqrt((a.q - b.q).squaredNorm() + (a.p - b.p).squaredNorm());
  return difference / std::sqrt(b.q.squaredNorm() + b.p.squaredNorm());
}

// Runs `steps` steps of h from `start`; returns the trajectory (start included), or stops at the
// first failure, whose status is stored in *failure when given.
std::vector<State> trajectory(const std::string& method, const Problem& problem, const State& start,
                              double h, int steps, StepStatus* failure = nullptr,
                              Counters* counters = nullptr) {
  auto integrator = make_integrator(method);
  State state = start;
  integrator->reset(problem, state, h);
  std::vector<State> out{state};
  for (int k = 0; k < steps; ++k) {
    const StepStatus status = integrator->step(problem, state, h);
    if (!status.ok) {
      if (failure) *failure = status;
      break;
    }
    out.push_back(state);
  }
  if (counters) *counters = integrator->counters();
  return out;
}

// Largest relative distance between two trajectories (INFINITY when either stopped early).
double max_distance(const std::vector<State>& a, const std::vector<State>& b) {
  if (a.size() != b.size()) return INFINITY;
  double worst = 0;
  for (size_t k = 0; k < a.size(); ++k) worst = std::max(worst, relative_distance(a[k], b[k]));
  return worst;
}

// ---------------------------------------------------------------------------------------------
// The generic forms reproduce the known schemes (docs/METHOD.md §1 table, §4).

TEST(Equivalence, DelAndHpReproduceTheKnownSchemesOnKepler) {
  const auto problem = make_problem("kepler:e=0.6");
  const State start = problem->initial_state();
  const double h = 0.01;
  const int steps = 1000;
  struct Pair {
    const char* method;
    const char* reference;
  };
  const Pair pairs[] = {
      // Kick first: L_d = h L(q_k, v) and HP α = 0 put ∇V at q_k.
      {"del:rule=left", "symplectic_euler_a"},
      {"hp:alpha=0", "symplectic_euler_a"},
      {"hp:alpha=0,solver=newton", "symplectic_euler_a"},
      {"del:rule=right", "symplectic_euler_b"},
      {"hp:alpha=1", "symplectic_euler_b"},
      {"del:rule=trapezoid", "stormer_verlet"},
      {"del:rule=symmetric_alpha,alpha=0", "stormer_verlet"},
      {"newmark:beta=0,gamma=0.5", "stormer_verlet"},
      {"del:rule=midpoint", "implicit_midpoint"},
      {"del:rule=alpha,alpha=0.5", "implicit_midpoint"},
      {"del:rule=symmetric_alpha,alpha=0.5", "implicit_midpoint"},
      {"hp:alpha=0.5,solver=minimize", "implicit_midpoint"},
      {"hp:alpha=0.5,solver=newton", "implicit_midpoint"},
  };
  for (const auto& [method, reference] : pairs) {
    const double distance = max_distance(trajectory(method, *problem, start, h, steps),
                                         trajectory(reference, *problem, start, h, steps));
    // Round-off and polished Newton solves (~1e-16 a step) over 1000 steps of a mildly
    // unstable (integrable, linearly diverging) flow.
    EXPECT_LE(distance, 1e-12) << method << " vs " << reference;
  }
}

TEST(Equivalence, DelAlphaRuleIsHpWithTheSameAlpha) {
  const auto problem = make_problem("kepler:e=0.6");
  const State start = problem->initial_state();
  for (const char* alpha : {"0.25", "0.75"}) {
    const auto del =
        trajectory(std::string("del:rule=alpha,alpha=") + alpha, *problem, start, 0.01, 1000);
    for (const char* solver : {"minimize", "newton"}) {
      const std::string hp = std::string("hp:alpha=") + alpha + ",solver=" + solver;
      EXPECT_LE(max_distance(trajectory(hp, *problem, start, 0.01, 1000), del), 1e-12) << hp;
    }
  }
}

// For a linear force the α-rule and Newmark (γ = ½, β = α(1 − α)) share the two-step recurrence
// M(q_{k+1} − 2q_k + q_{k−1})/h² = −K[βq_{k−1} + (1 − 2β)q_k + βq_{k+1}] (docs/METHOD.md §1).
TEST(Equivalence, NewmarkAndAlphaRuleShareTheRecurrenceForLinearForces) {
  const double omega = 1.7, h = 0.3;
  const auto problem = make_problem("harmonic:omega=1.7,q0=0.8,v0=0.4");
  for (const double alpha : {0.25, 0.5}) {
    const double beta = alpha * (1 - alpha);
    for (const std::string& method : {"del:rule=alpha,alpha=" + format_number(alpha),
                                      "newmark:beta=" + format_number(beta) + ",gamma=0.5"}) {
      const auto path = trajectory(method, *problem, problem->initial_state(), h, 50);
      ASSERT_EQ(path.size(), 51u) << method;
      double worst = 0;
      for (size_t k = 1; k + 1 < path.size(); ++k) {
        const double q0 = path[k - 1].q[0], q1 = path[k].q[0], q2 = path[k + 1].q[0];
        const double lhs = (q2 - 2 * q1 + q0) / (h * h);
        const double rhs = -omega * omega * (beta * q0 + (1 - 2 * beta) * q1 + beta * q2);
        worst = std::max(worst, std::abs(lhs - rhs));
      }
      EXPECT_LE(worst, 1e-12) << method;
    }
  }
}

TEST(Equivalence, ImplicitMidpointWithForceIsTheSplitMidpointImpulse) {
  // F_d⁻ = F_d⁺ = (h/2)F(q_{k+½}, v): del/hp with force_slot=split, force_at=midpoint.
  for (const char* problem_spec :
       {"damped_oscillator:zeta=0.2", "spring_net:nx=3,ny=3,damping=2"}) {
    const auto problem = make_problem(problem_spec);
    const auto reference =
        trajectory("implicit_midpoint", *problem, problem->initial_state(), 0.02, 300);
    for (const char* method :
         {"del:force_slot=split,force_at=midpoint", "hp:force_slot=split,force_at=midpoint",
          "hp:force_slot=split,force_at=midpoint,solver=newton"}) {
      EXPECT_LE(max_distance(trajectory(method, *problem, problem->initial_state(), 0.02, 300),
                             reference),
                1e-12)
          << method << " on " << problem_spec;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Symplecticity of one step: ‖JᵀΩJ − Ω‖ with J = ∂(q₁, p₁)/∂(q₀, p₀) by central differences.

double symplecticity_defect(const std::string& method) {
  const auto problem = make_problem("kepler:e=0.6");
  const double h = 0.05;
  State base;
  // A generic point (off the symmetry axes) close to the centre, r ≈ 0.34, where hω ≈ 0.3: RK4's
  // defect is O((hω)⁵) per step and would hide under 1e-4 at a gentler point (1.7e-8 at r = 0.85).
  base.q = Eigen::Vector2d(0.3, 0.15);
  base.p = Eigen::Vector2d(-0.6, 1.9);
  auto integrator = make_integrator(method);
  const auto step = [&](const Eigen::Vector4d& y) -> Eigen::Vector4d {
    State state{0.0, y.head<2>(), y.tail<2>()};
    integrator->reset(*problem, state, h);
    if (!integrator->step(*problem, state, h).ok) return Eigen::Vector4d::Constant(NAN);
    Eigen::Vector4d out;
    out << state.q, state.p;
    return out;
  };
  Eigen::Vector4d y;
  y << base.q, base.p;
  // δ = 1e-6: truncation δ² ~ 1e-12 and round-off ε/δ ~ 1e-10 (solver noise at its round-off
  // floor too), so a symplectic map shows ≲ 1e-9 and 1e-8 separates it from a real defect.
  const double delta = 1e-6;
  Eigen::Matrix4d jacobian;
  for (int j = 0; j < 4; ++j) {
    Eigen::Vector4d plus = y, minus = y;
    plus[j] += delta;
    minus[j] -= delta;
    jacobian.col(j) = (step(plus) - step(minus)) / (2 * delta);
  }
  Eigen::Matrix4d omega = Eigen::Matrix4d::Zero();
  omega.topRightCorner<2, 2>() = Eigen::Matrix2d::Identity();
  omega.bottomLeftCorner<2, 2>() = -Eigen::Matrix2d::Identity();
  return (jacobian.transpose() * omega * jacobian - omega).norm();
}

std::vector<std::string> symplectic_methods() {
  std::vector<std::string> out;
  for (const auto& spec : integrator_test_specs()) {
    const unsigned flags = make_integrator(spec)->info().flags;
    // Constrained-only methods cannot run on the unconstrained test problem (applicable());
    // tests/constraints_test.cpp checks them on the constraint manifold, and
    // integrators/lie_poisson_test.cpp the free-rigid-body splitting.
    if ((flags & kSymplectic) && !(flags & (kAdaptive | kConstraintsOnly | kFreeRigidBodyOnly))) {
      out.push_back(spec);
    }
  }
  // Forcing options do not touch an unforced step, but the spec must still give a symplectic map.
  out.push_back("hp:alpha=0.75,solver=newton");
  out.push_back("del:rule=symmetric_alpha,alpha=0.1,force_slot=minus");
  return out;
}

class SymplecticMethod : public testing::TestWithParam<std::string> {};

TEST_P(SymplecticMethod, OneStepPreservesTheSymplecticForm) {
  EXPECT_LE(symplecticity_defect(GetParam()), 1e-8);
}

INSTANTIATE_TEST_SUITE_P(Registry, SymplecticMethod, testing::ValuesIn(symplectic_methods()),
                         test_name);

TEST(NegativeControl, SymplecticityDefectIsLargeForNonSymplecticMethods) {
  EXPECT_GT(symplecticity_defect("rk4"), 1e-4);
  EXPECT_GT(symplecticity_defect("implicit_euler"), 1e-4);
  EXPECT_GT(symplecticity_defect("explicit_euler"), 1e-4);
  // Newmark β > 0 conserves a non-canonical symplectic form only (Kane et al. 2000): the
  // canonical defect is small but far above the finite-difference noise.
  EXPECT_GT(symplecticity_defect("newmark:beta=0.25,gamma=0.5"), 1e-4);
}

// ---------------------------------------------------------------------------------------------
// Discrete Noether on a free spring network (docs/METHOD.md claim 1).

// verify::momentum_errors (verify/verify.hpp): max |ΔL|/|L₀|, |ΔJ|/|J₀| and J_N − J₀ of a run.
using verify::momentum_errors;
using verify::MomentumErrors;

std::vector<std::string> variational_methods() {
  std::vector<std::string> out;
  for (const auto& spec : integrator_test_specs()) {
    const unsigned flags = make_integrator(spec)->info().flags;
    if ((flags & kVariational) && !(flags & (kAdaptive | kConstraintsOnly | kFreeRigidBodyOnly))) {
      out.push_back(spec);
    }
  }
  return out;
}

class VariationalMethod : public testing::TestWithParam<std::string> {};

TEST_P(VariationalMethod, KeepsSpringNetMomentaOver10000Steps) {
  // verify::momentum_maps_kept's defaults: spring_net:nx=4,ny=4, 1e4 steps of 0.01, both relative
  // errors <= 1e-12: round-off and polished solves; a tolerance-level solve would show ~1e-10.
  const verify::CheckResult result = verify::momentum_maps_kept(GetParam());
  EXPECT_TRUE(result.passed) << verify::describe(result);
}

INSTANTIATE_TEST_SUITE_P(Registry, VariationalMethod, testing::ValuesIn(variational_methods()),
                         test_name);

TEST(NegativeControl, NewmarkDoesNotKeepSpringNetAngularMomentum) {
  // Newmark β > 0 is not the α-rule VI for nonlinear forces (docs/METHOD.md §1): linear momentum is
  // kept (pairwise forces), angular momentum is not.
  const MomentumErrors errors =
      momentum_errors("newmark:beta=0.25,gamma=0.5", "spring_net:nx=4,ny=4", 0.01, 10000);
  ASSERT_TRUE(errors.ok);
  EXPECT_LE(errors.linear, 1e-12);
  EXPECT_GT(errors.angular, 1e-8);
}

// ---------------------------------------------------------------------------------------------
// Forced discrete Noether on the damped spring network (docs/METHOD.md §2). Predicted: each impulse
// evaluated at its own node is torque-free about the point where it acts, so every slot keeps
// both momenta; evaluated at q_{k+½} the minus (plus) impulse has torque −(h/2)Σv×F (+(h/2)Σv×F)
// about q_k (q_{k+1}): O(h²) a step, O(h) over [0, T], opposite signs; split cancels.

constexpr const char* kDampedNet = "spring_net:nx=4,ny=4,damping=1";

TEST(ForceSlots, NodeEvaluationKeepsMomentaInEverySlot) {
  for (const char* base :
       {"del", "del:rule=trapezoid,", "hp", "hp:solver=newton,", "hp:alpha=0.25,"}) {
    for (const char* slot : {"minus", "plus", "split"}) {
      std::string method = base;
      method += method.back() == ',' ? "" : ":";
      method += std::string("force_at=node,force_slot=") + slot;
      const MomentumErrors errors = momentum_errors(method, kDampedNet, 0.01, 2000);
      ASSERT_TRUE(errors.ok) << method;
      EXPECT_LE(errors.linear, 1e-10) << method;
      EXPECT_LE(errors.angular, 1e-10) << method;
    }
  }
}

TEST(ForceSlots, MidpointEvaluationDriftsInMinusAndPlusAtFirstOrder) {
  for (const char* base : {"del:", "hp:", "hp:solver=newton,"}) {
    const std::string prefix = std::string(base) + "force_at=midpoint,force_slot=";
    const MomentumErrors minus = momentum_errors(prefix + "minus", kDampedNet, 0.01, 2000);
    const MomentumErrors plus = momentum_errors(prefix + "plus", kDampedNet, 0.01, 2000);
    const MomentumErrors split = momentum_errors(prefix + "split", kDampedNet, 0.01, 2000);
    ASSERT_TRUE(minus.ok && plus.ok && split.ok) << base;
    // Measured ≈ 1e-4 relative over t ∈ [0, 20] at h = 0.01: far above the solver tolerance.
    EXPECT_GT(minus.angular, 1e-6) << base;
    EXPECT_GT(plus.angular, 1e-6) << base;
    EXPECT_LT(minus.angular_final[0] * plus.angular_final[0], 0.0) << base << " opposite torques";
    EXPECT_LE(minus.linear, 1e-10) << base;
    EXPECT_LE(plus.linear, 1e-10) << base;
    EXPECT_LE(split.linear, 1e-10) << base;
    EXPECT_LE(split.angular, 1e-10) << base;
    // O(h) over a fixed time: halving h halves the drift.
    const MomentumErrors minus_half = momentum_errors(prefix + "minus", kDampedNet, 0.005, 4000);
    ASSERT_TRUE(minus_half.ok);
    EXPECT_NEAR(minus.angular_final[0] / minus_half.angular_final[0], 2.0, 0.3) << base;
  }
}

// The signed law behind the drift, step by step: forced discrete Noether gives J_{k+1} − J_k =
// Σ_i q_k,i × F⁻_i + Σ_i q_{k+1},i × F⁺_i, and with the impulse hF(q_{k+½}, v) torque-free about
// q_{k+½} = q_k + (h/2)v this is −(h²/2)Σ_i v_i × F_i for the minus slot and +(h²/2)Σ_i v_i × F_i
// for plus. The prediction is recomputed from the trajectory itself (v = (q_{k+1} − q_k)/h), so the
// check is an identity to solver tolerance, with the sign: it tells the slots apart (the
// magnitude-only checks above pass with minus and plus swapped).
TEST(ForceSlots, MidpointDriftFollowsTheSignedImpulseTorqueOfItsSlot) {
  const auto problem = make_problem(kDampedNet);
  const double h = 0.01;
  const int steps = 500;
  for (const char* base : {"del:", "hp:", "hp:solver=newton,"}) {
    for (const double sign : {-1.0, 1.0}) {
      const std::string method =
          std::string(base) + "force_at=midpoint,force_slot=" + (sign < 0 ? "minus" : "plus");
      const auto path = trajectory(method, *problem, problem->initial_state(), h, steps);
      ASSERT_EQ(path.size(), static_cast<size_t>(steps + 1)) << method;
      double predicted = 0, measured = 0, scale = 0;
      Vec force;
      for (int k = 0; k < steps; ++k) {
        const Vec v = (path[k + 1].q - path[k].q) / h;
        force_of(*problem).force(path[k].q + (h / 2) * v, v, path[k].t + h / 2, force);
        double torque = 0;  // Σ_i v_i × F_i (planar)
        for (Eigen::Index i = 0; i + 1 < v.size(); i += 2) {
          torque += v[i] * force[i + 1] - v[i + 1] * force[i];
        }
        const double change = problem->angular_momentum(path[k + 1].q, path[k + 1].p)[0] -
                              problem->angular_momentum(path[k].q, path[k].p)[0];
        predicted += sign * (h * h / 2) * torque;
        measured += change;
        scale += std::abs(sign * (h * h / 2) * torque);
      }
      // The accumulated change is well above round-off of L ≈ 323 (≈ 1e-13 a step) and has the
      // predicted sign; solver tolerance and round-off leave < 1e-6 of it.
      ASSERT_GT(scale, 1e-6) << method;
      EXPECT_GT(measured * predicted, 0.0)
          << method << ": measured " << measured << ", predicted " << predicted;
      EXPECT_NEAR(measured, predicted, 1e-6 * scale) << method;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Energy decay of the damped oscillator q̈ + 2ζωq̇ + ω²q = 0 (docs/METHOD.md §2, Fig. 1).

// Largest |H(q_k, p_k) − H(exact(t_k))| over t ∈ [0, 20], and its signed value at t = 20.
std::pair<double, double> energy_decay_error(const std::string& method, double h) {
  const auto problem = make_problem("damped_oscillator:zeta=0.1");
  const auto path = trajectory(method, *problem, problem->initial_state(), h,
                               static_cast<int>(std::lround(20 / h)));
  double worst = 0, last = NAN;
  for (const State& state : path) {
    const State exact = problem->exact(state.t);
    last = problem->energy(state.q, state.p) - problem->energy(exact.q, exact.p);
    worst = std::max(worst, std::abs(last));
  }
  return {worst, last};
}

TEST(DampedOscillator, SplitImpulseMidpointTracksTheDecayAtSecondOrder) {
  // The impulse h·F split evenly between the two ends is the trapezoidal quadrature of the virtual
  // work, consistent to second order; all of it in one slot is a one-sided quadrature (first
  // order in the force coupling), measured here too.
  for (const char* method :
       {"del:force_slot=split,force_at=node", "hp:force_slot=split,force_at=node",
        "hp:force_slot=split,force_at=node,solver=newton", "del:force_slot=split,force_at=midpoint",
        "hp:force_slot=split,force_at=midpoint", "implicit_midpoint",
        "del:rule=trapezoid,force_slot=split"}) {
    const double coarse = energy_decay_error(method, 0.05).first;
    const double fine = energy_decay_error(method, 0.025).first;
    EXPECT_NEAR(coarse / fine, 4.0, 0.3) << method;
    EXPECT_LT(fine, 1e-3) << method;
  }
  for (const char* method :
       {"del:force_slot=plus,force_at=node", "del:force_slot=minus", "hp:force_slot=plus"}) {
    const double coarse = energy_decay_error(method, 0.05).first;
    const double fine = energy_decay_error(method, 0.025).first;
    EXPECT_NEAR(coarse / fine, 2.0, 0.3) << method << " (one-sided impulse: first order)";
  }
}

TEST(DampedOscillator, EulerMethodsAddAndRemoveNumericalDamping) {
  const auto [vi, vi_final] = energy_decay_error("del:force_slot=split", 0.05);
  const auto [implicit, implicit_final] = energy_decay_error("implicit_euler", 0.05);
  const auto [explicit_error, explicit_final] = energy_decay_error("explicit_euler", 0.05);
  EXPECT_LT(implicit_final, 0.0) << "implicit Euler should sit below the exact energy";
  EXPECT_GT(explicit_final, 0.0) << "explicit Euler should sit above the exact energy";
  EXPECT_GT(implicit, 20 * vi);
  EXPECT_GT(explicit_error, 20 * vi);
}

// ---------------------------------------------------------------------------------------------
// The two HP solvers (docs/METHOD.md §4).

TEST(HpSolvers, ReturnTheSameStepWhereBothConverge) {
  struct Case {
    const char* problem;
    double h;
    const char* options;
  };
  const Case cases[] = {
      {"pendulum:theta0=1.5", 0.1, ""},
      {"pendulum:theta0=2.5", 0.5, ",alpha=0.3"},
      {"kepler:e=0.6", 0.05, ""},
      {"spring_net:nx=4,ny=4,model=nonlinear", 0.02, ""},
      // Dissipation-potential objective (minus at the node) and the ½‖R‖² fallback (midpoint).
      {kDampedNet, 0.02, ",force_slot=minus,force_at=node"},
      {kDampedNet, 0.02, ",force_slot=split,force_at=midpoint"},
      {"damped_oscillator:zeta=0.3", 0.1, ",force_slot=minus,force_at=node,alpha=0.7"},
  };
  for (const auto& [problem_spec, h, options] : cases) {
    const auto problem = make_problem(problem_spec);
    StepStatus minimize_status, newton_status;
    const auto minimize = trajectory(std::string("hp:solver=minimize") + options, *problem,
                                     problem->initial_state(), h, 20, &minimize_status);
    const auto newton = trajectory(std::string("hp:solver=newton") + options, *problem,
                                   problem->initial_state(), h, 20, &newton_status);
    ASSERT_EQ(minimize.size(), 21u) << problem_spec << options << ": " << minimize_status.message;
    ASSERT_EQ(newton.size(), 21u) << problem_spec << options << ": " << newton_status.message;
    EXPECT_LE(max_distance(minimize, newton), 1e-12) << problem_spec << options;
  }
}

TEST(HpSolvers, OneIterationOnAHardStepFailsWithAReason) {
  const auto problem = make_problem("pendulum:theta0=3.0");
  for (const char* method : {"hp:max_iter=1", "hp:max_iter=1,solver=newton", "del:max_iter=1",
                             "implicit_midpoint:max_iter=1", "newmark:max_iter=1"}) {
    StepStatus status;
    const auto path = trajectory(method, *problem, problem->initial_state(), 2.0, 1, &status);
    EXPECT_EQ(path.size(), 1u) << method;
    EXPECT_FALSE(status.ok) << method;
    EXPECT_EQ(status.reason, "newton_max_iter") << method;
    EXPECT_NE(status.message.find("residual"), std::string::npos) << status.message;
  }
}

// Hard regimes: the minimiser's line search on E_k and SPD shift versus plain Newton on R. Counts
// are recorded (RecordProperty), not asserted: speed is the benchmark's business.
TEST(HpSolvers, MinimiserSucceedsWherePlainNewtonFails) {
  struct Case {
    const char* problem;
    double h;
    int steps;
  };
  const Case cases[] = {
      // Pendulum from near the top at h = 3: E_k is non-convex (cos θ < 0) and plain Newton
      // jumps between basins.
      {"pendulum:theta0=3.0", 3.0, 200},
      // Stiff quartic springs under large deformation at h ≈ 0.3·(2/ω_max).
      {"spring_net:nx=4,ny=4,model=nonlinear,stiffness=1000,velocity=3", 0.1, 100},
  };
  for (const auto& [problem_spec, h, steps] : cases) {
    const auto problem = make_problem(problem_spec);
    StepStatus minimize_status, newton_status;
    Counters minimize_work, newton_work;
    const auto minimize = trajectory("hp:solver=minimize", *problem, problem->initial_state(), h,
                                     steps, &minimize_status, &minimize_work);
    const auto newton = trajectory("hp:solver=newton", *problem, problem->initial_state(), h, steps,
                                   &newton_status, &newton_work);
    EXPECT_EQ(static_cast<int>(minimize.size()), steps + 1)
        << problem_spec << ": " << minimize_status.message;
    EXPECT_LT(static_cast<int>(newton.size()), steps + 1) << problem_spec;
    EXPECT_FALSE(newton_status.reason.empty());
    RecordProperty(std::string(problem_spec) + " minimize newton_iters/step",
                   std::to_string(double(minimize_work.newton_iters) / minimize_work.steps));
    RecordProperty(std::string(problem_spec) + " newton steps before failure",
                   std::to_string(newton_work.steps));
  }
}

// A free neo-Hookean bar spinning about (1,1,1)/√3: after ~2.3 rad of rotation H = F − I is of
// size 1 in every element, so the energy density μ(tr H + ½|H|²) − μ ln J ~ strain² carries
// rounding ~ε·μ·vol·|H| — about 120ε·objective_scale, beyond what the line search's value test
// allows — while the gradient stays accurate. Before the derivative-form Armijo test
// (kApproximateArmijoSlack) the minimiser stopped there (line_search_failed or newton_max_iter)
// at every scale of the bar, while plain Newton ran through. Scales: SI-sized, 1000× shorter
// (time and h scale with it), material 1e-9× lighter and softer.
TEST(HpSolvers, MinimiserRunsTheSpinningFreeBarAtEveryScale) {
  struct Case {
    const char* scale;  // appended to the bar's spec
    double h;
  };
  const std::string bar =
      "elastic_bar:clamp=none,nx=2,ny=1,nz=1,gravity=0,init=velocity,twist=0.5,shake=0.5,";
  const Case cases[] = {
      {"spin=1,bend=0.05", 0.01},
      {"spin=1000,bend=5e-5,length=1e-3,width=2e-4,height=2e-4", 1e-5},
      {"spin=1,bend=0.05,density=1e-6,young=1e-4", 0.01},
  };
  for (const auto& [scale, h] : cases) {
    const auto problem = make_problem(bar + scale);
    StepStatus minimize_status, newton_status;
    const auto minimize = trajectory("hp:solver=minimize", *problem, problem->initial_state(), h,
                                     300, &minimize_status);
    const auto newton =
        trajectory("hp:solver=newton", *problem, problem->initial_state(), h, 300, &newton_status);
    ASSERT_EQ(newton.size(), 301u) << scale << ": " << newton_status.message;
    ASSERT_EQ(minimize.size(), 301u) << scale << ": " << minimize_status.message;
    EXPECT_LE(max_distance(minimize, newton), 1e-12) << scale;
  }
}

// ---------------------------------------------------------------------------------------------
// Declared properties, caches, counters and parameters.

TEST(Declared, OrdersAndFlagsFollowTheRule) {
  struct Expect {
    const char* spec;
    int order;
    unsigned flags;
  };
  const unsigned vi = kSymplectic | kVariational;
  const unsigned implicit = kImplicit | kNeedsHessian;
  const unsigned general = kGeneralLagrangian;  // one interior node: runs any L(q, v)
  const Expect table[] = {
      {"del:rule=left", 1, vi | kExplicit},
      {"del:rule=right", 1, vi | kExplicit},
      {"del:rule=trapezoid", 2, vi | kExplicit | kSymmetric},
      {"del:rule=midpoint", 2, vi | implicit | kSymmetric | kConstrained | kRheonomic | general},
      {"del:rule=alpha,alpha=0.5", 2,
       vi | implicit | kSymmetric | kConstrained | kRheonomic | general},
      {"del:rule=alpha,alpha=0.25", 1, vi | implicit | general},
      {"del:rule=alpha,alpha=0", 1, vi | kExplicit},
      {"del:rule=symmetric_alpha,alpha=0.25", 2, vi | implicit | kSymmetric},
      {"del:rule=symmetric_alpha,alpha=1", 2, vi | kExplicit | kSymmetric},
      // hp runs the general kind unless solver=minimize is written out (no scalar objective).
      {"hp", 2, vi | implicit | kSymmetric | kConstrained | kRheonomic | general},
      {"hp:solver=minimize", 2, vi | implicit | kSymmetric | kConstrained | kRheonomic},
      {"hp:alpha=0.25,solver=newton", 1, vi | implicit | general},
      {"hp:alpha=0.25,solver=minimize", 1, vi | implicit},
      {"hp:alpha=0", 1, vi | kExplicit},
      {"hp:alpha=1", 1, vi | kExplicit},
      {"newmark", 2, implicit | kSymmetric},
      {"newmark:beta=0.25,gamma=0.6", 1, implicit},
      {"newmark:beta=0,gamma=0.5", 2, vi | kExplicit | kSymmetric},
      {"newmark:beta=0,gamma=0.7", 1, kExplicit},
      {"implicit_midpoint", 2, vi | implicit | kSymmetric | general},
  };
  for (const auto& [spec, order, flags] : table) {
    const MethodInfo info = make_integrator(spec)->info();
    EXPECT_EQ(info.order, order) << spec;
    EXPECT_EQ(info.flags, flags) << spec << ": " << testing::PrintToString(flag_names(info.flags));
  }
}

TEST(Declared, CanonicalSpecsReadAlphaOnlyWhereTheRuleUsesIt) {
  EXPECT_EQ(make_integrator("del")->spec(),
            "del:force_at=midpoint,force_slot=split,max_iter=50,rule=midpoint,tol=1e-12");
  EXPECT_EQ(make_integrator("del:rule=alpha")->spec(),
            "del:alpha=0.5,force_at=midpoint,force_slot=split,max_iter=50,rule=alpha,tol=1e-12");
  EXPECT_EQ(make_integrator("hp")->spec(),
            "hp:alpha=0.5,force_at=midpoint,force_slot=split,max_iter=50,solver=minimize,"
            "tol=1e-12");
  EXPECT_EQ(make_integrator("newmark")->spec(),
            "newmark:beta=0.25,gamma=0.5,max_iter=50,tol=1e-12");
}

TEST(Counters, ExplicitRulesSolveNothingAndReuseTheEndGradient) {
  const auto problem = make_problem("kepler:e=0.6");
  for (const char* method : {"del:rule=trapezoid", "newmark:beta=0,gamma=0.5"}) {
    Counters work;
    trajectory(method, *problem, problem->initial_state(), 0.01, 100, nullptr, &work);
    EXPECT_EQ(work.newton_iters, 0) << method;
    EXPECT_EQ(work.hessian_evals, 0) << method;
    // One gradient a step after the first (first same as last).
    EXPECT_EQ(work.force_evals, 101) << method;
  }
  Counters work;
  trajectory("hp:alpha=0", *problem, problem->initial_state(), 0.01, 100, nullptr, &work);
  EXPECT_EQ(work.newton_iters, 0);
  EXPECT_EQ(work.force_evals, 100);
}

// energy_evals counts each point at which the minimiser used E_k (its first value and every line
// search trial), whether the problem computed V on its own or with ∇V in one pass
// (Problem::potential_with_gradient: the elastic bar; the pendulum has none), so the counter and
// the committed rows do not depend on how V was obtained.
TEST(Counters, MinimiserCountsEveryEnergyItUsesHoweverItWasComputed) {
  for (const char* spec : {"elastic_bar:nx=3,ny=1,nz=1", "pendulum:theta0=1.5"}) {
    const auto problem = make_problem(spec);
    Vec g;
    double V = 0;
    const bool one_pass = problem->potential_with_gradient(problem->initial_state().q, g, V);
    EXPECT_EQ(one_pass, std::string(spec).starts_with("elastic_bar")) << spec;
    const NewtonProfile before = newton_profile();
    Counters work;
    trajectory("hp", *problem, problem->initial_state(), 0.01, 20, nullptr, &work);
    const NewtonProfile after = newton_profile();
    EXPECT_GT(work.energy_evals, 20) << spec;
    EXPECT_EQ(work.energy_evals, after.objectives - before.objectives) << spec;
  }
}

TEST(Counters, MinimiserCountsLineSearchEnergiesAndPlainNewtonNone) {
  const auto problem = make_problem("pendulum:theta0=1.5");
  Counters minimize, newton;
  trajectory("hp", *problem, problem->initial_state(), 0.1, 50, nullptr, &minimize);
  trajectory("hp:solver=newton", *problem, problem->initial_state(), 0.1, 50, nullptr, &newton);
  EXPECT_GT(minimize.energy_evals, minimize.newton_iters);  // ≥ 1 trial per iteration, plus E(v₀)
  EXPECT_EQ(newton.energy_evals, 0);
  EXPECT_EQ(minimize.newton_iters, newton.newton_iters);  // easy steps: full Newton steps
  EXPECT_EQ(minimize.hessian_evals, minimize.newton_iters);
  EXPECT_EQ(minimize.linear_solves, minimize.newton_iters);
}

TEST(Counters, NewmarkRecomputesTheAccelerationWhenTheStateIsEdited) {
  const auto problem = make_problem("kepler:e=0.6");
  auto cached = make_integrator("newmark");
  State state = problem->initial_state();
  cached->reset(*problem, state, 0.01);
  ASSERT_TRUE(cached->step(*problem, state, 0.01).ok);
  state.p *= 1.01;  // an external edit: the cached a₀ must not be used
  State edited = state;
  ASSERT_TRUE(cached->step(*problem, state, 0.01).ok);
  auto fresh = make_integrator("newmark");
  fresh->reset(*problem, edited, 0.01);
  ASSERT_TRUE(fresh->step(*problem, edited, 0.01).ok);
  EXPECT_EQ(state.q, edited.q);
  EXPECT_EQ(state.p, edited.p);
}

TEST(Stiffness, TrapezoidalNewmarkConvergesFarBeyondTheExplicitLimit) {
  // Newmark(1/4, 1/2) is unconditionally stable; at hω = 1e3 the residual's terms are (hω)²
  // larger than ‖p‖, so a tolerance relative to ‖p‖ alone would be below their round-off and
  // every step would "fail" (found by the alpha_family stability search).
  const auto problem = make_problem("harmonic");
  auto newmark = make_integrator("newmark:beta=0.25,gamma=0.5");
  State state = problem->initial_state();
  const double energy0 = problem->energy(state.q, state.p);
  newmark->reset(*problem, state, 1000.0);
  for (int step = 0; step < 1000; ++step) {
    const StepStatus status = newmark->step(*problem, state, 1000.0);
    ASSERT_TRUE(status.ok) << "step " << step << ": " << status.message;
  }
  // The trapezoidal rule conserves the quadratic energy of a linear system to round-off.
  EXPECT_NEAR(problem->energy(state.q, state.p), energy0, 1e-9 * energy0);
}

TEST(Parameters, BadValuesAndUnknownKeysNameTheKey) {
  const test::InputErrorCases cases = {
      {"hp:alpha=1.5", "alpha"},
      {"hp:alpha=-0.1", "alpha"},
      {"hp:solver=cg", "solver"},
      {"hp:max_iter=0", "max_iter"},
      {"hp:tol=0", "tol"},
      {"hp:force_slot=middle", "force_slot"},
      {"del:force_at=end", "force_at"},
      {"del:rule=nope", "rule"},
      {"del:rule=midpoint,alpha=0.3", "alpha"},  // midpoint has no alpha
      {"del:rule=alpha,alpha=2", "alpha"},
      {"newmark:beta=-1", "beta"},
      {"newmark:beta=0.6", "beta"},
      {"newmark:gamma=1.5", "gamma"},
      {"newmark:delta=1", "delta"},
      {"implicit_midpoint:alpha=0.5", "alpha"},
      {"hp:foo=1", "foo"},
  };
  EXPECT_TRUE(test::input_errors_name(make_integrator, cases));
}

// ---------------------------------------------------------------------------------------------
// The Newton solver extensions the minimiser relies on (integrators/newton.hpp).

SparseMatrix one_by_one(double value) {
  SparseMatrix m(1, 1);
  m.insert(0, 0) = value;
  m.makeCompressed();
  return m;
}

TEST(NewtonExtensions, SpdShiftTurnsAClimbingStepIntoDescent) {
  // E(x) = −cos x at x = 2: E'' < 0, so the Newton step climbs; shifted, it descends to x = 0.
  NewtonSystem concave;
  concave.symmetric = true;
  concave.objective = [](const Vec& x) { return -std::cos(x[0]); };
  concave.residual = [](const Vec& x, Vec& r) { r = Vec::Constant(1, std::sin(x[0])); };
  concave.jacobian = [](const Vec& x, SparseMatrix& J) { J = one_by_one(std::cos(x[0])); };
  concave.spd_shift = one_by_one(1.0);
  Vec x = Vec::Constant(1, 2.0);
  const NewtonResult result = NewtonSolver().solve(concave, x, 1.0);
  ASSERT_TRUE(result.converged) << describe(result);
  EXPECT_LE(std::abs(x[0]), 1e-12);
  EXPECT_GE(result.shifted_iterations, 1);
  EXPECT_GE(result.shift_factorisations, result.shifted_iterations);
}

TEST(NewtonExtensions, PolishTakesTheResidualToRoundOff) {
  NewtonSystem system;
  system.symmetric = true;
  system.residual = [](const Vec& x, Vec& r) {
    r = Vec::Constant(1, x[0] + 0.1 * std::sin(x[0]) - 1);
  };
  system.jacobian = [](const Vec& x, SparseMatrix& J) { J = one_by_one(1 + 0.1 * std::cos(x[0])); };
  NewtonOptions options;
  options.tolerance = 1e-6;  // met at ~2.5e-9 after two updates
  Vec x = Vec::Constant(1, 1.0);
  const NewtonResult plain = NewtonSolver(options).solve(system, x, 1.0);
  ASSERT_TRUE(plain.converged);
  EXPECT_GT(plain.residual_norm, 1e-12);
  options.polish = true;
  x = Vec::Constant(1, 1.0);
  const NewtonResult polished = NewtonSolver(options).solve(system, x, 1.0);
  ASSERT_TRUE(polished.converged);
  EXPECT_TRUE(polished.polished);
  EXPECT_EQ(polished.iterations, plain.iterations);
  // A simplified step with the previous iterate's Jacobian: error ~ K·e_{n−1}·e_n, here
  // 2.6e-4 · 2.5e-9 (at tolerance 1e-12 that is the round-off floor).
  EXPECT_LE(polished.residual_norm, 1e-4 * plain.residual_norm);
}

TEST(NewtonExtensions, ObjectiveScaleLetsTheLineSearchSeePastCancellation) {
  // E = (B + ½(x − 1)² + (x − 1)⁴) − B with B = 1e6: E is small but carries B's round-off
  // (~1e-10), far above the decrease of the last Newton steps. Told the terms' size, the line
  // search accepts residual-reducing steps inside that noise and converges.
  const double big = 1e6;
  NewtonSystem system;
  system.symmetric = true;
  system.objective = [&](const Vec& x) {
    const double d = x[0] - 1;
    return (big + 0.5 * d * d + d * d * d * d) - big;
  };
  system.residual = [](const Vec& x, Vec& r) {
    const double d = x[0] - 1;
    r = Vec::Constant(1, d + 4 * d * d * d);
  };
  system.jacobian = [](const Vec& x, SparseMatrix& J) {
    const double d = x[0] - 1;
    J = one_by_one(1 + 12 * d * d);
  };
  system.objective_scale = big;
  Vec x = Vec::Constant(1, 1.5);
  const NewtonResult result = NewtonSolver().solve(system, x, 1.0);
  ASSERT_TRUE(result.converged) << describe(result);
  EXPECT_LE(std::abs(x[0] - 1), 1e-12);
}

TEST(NewtonExtensions, DerivativeArmijoDoesNotClimbIntoAnotherWell) {
  // E = x²(x + 2)² − x/2: the well near x = 0.06 is deeper than the one near −1.94 (E ≈ 0.98).
  // From x = 0.3 (E ≈ 0.33) a first Jacobian that sends the step to the shallow well's bottom
  // cuts ‖R‖ and leaves a slope that passes the derivative-form Armijo test, but E rises by 0.66:
  // the kApproximateArmijoSlack guard must reject it, so the solve ends in the deeper well.
  NewtonSystem system;
  system.symmetric = true;
  system.objective = [](const Vec& x) {
    const double y = x[0];
    return y * y * (y + 2) * (y + 2) - 0.5 * y;
  };
  const auto gradient = [](double y) { return 4 * y * (y + 1) * (y + 2) - 0.5; };
  system.residual = [&](const Vec& x, Vec& r) { r = Vec::Constant(1, gradient(x[0])); };
  const double start = 0.3, shallow_bottom = -1.9375;  // 8(x + 2) ≈ 0.5 there
  int jacobians = 0;
  system.jacobian = [&](const Vec& x, SparseMatrix& J) {
    const double y = x[0];
    J = one_by_one(jacobians++ == 0 ? gradient(start) / (start - shallow_bottom)
                                    : 12 * y * y + 24 * y + 8);
  };
  Vec x = Vec::Constant(1, start);
  const NewtonResult result = NewtonSolver().solve(system, x, 1.0);
  ASSERT_TRUE(result.converged) << describe(result);
  EXPECT_GT(x[0], -1.0) << "the solve climbed into the shallow well";
  EXPECT_NEAR(gradient(x[0]), 0.0, 1e-12);
}

TEST(NewtonExtensions, CentralDifferenceJacobianMatchesTheAnalyticOne) {
  const auto f = [](const Vec& x, Vec& out) {
    out.resize(2);
    out << x[0] * x[1], std::sin(x[0]) + x[1] * x[1] * x[1];
  };
  Vec x(2);
  x << 0.7, -1.3;
  const Eigen::MatrixXd J = Eigen::MatrixXd(central_difference_jacobian(f, x));
  Eigen::Matrix2d exact;
  exact << x[1], x[0], std::cos(x[0]), 3 * x[1] * x[1];
  // Truncation δ²f''' ~ 1e-10 and round-off ε/δ ~ 1e-11 with δ = ε^(1/3)·max(1, |x|).
  EXPECT_LE((J - exact).cwiseAbs().maxCoeff(), 1e-8);
}

}  // namespace
}  // namespace variational_test
}  // namespace geomint
