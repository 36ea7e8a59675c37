// The engine methods against the problems they model: the engine's own mass matrix, potential
// and kinetic energy equal the problem's (fidelity); on the pendulum each engine integrator that is
// a textbook scheme reproduces geomint's implementation of that scheme (identification); engine
// warnings end a run as a failed status; refusals name the problems that apply.
#include <gtest/gtest.h>

#include <random>

#include "engines/bullet.hpp"
#include "engines/mujoco.hpp"
#include "engines/ode.hpp"
#include "engines/planar_chain.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"
#include "verify/verify.hpp"

namespace geomint::engines {
namespace {

// Every chain problem at its defaults and at non-unit parameters (so a swapped mass or length
// shows), up to the longest rod chain the problem allows.
const std::vector<std::string> kChainSpecs = {
    "pendulum",
    "pendulum:omega0=2.5,theta0=1.2,v0=0.3",
    "double_pendulum",
    "double_pendulum:m1=1.3,m2=0.7,l1=0.9,l2=1.6,g=2.5,theta1=0.3,theta2=-0.2,omega1=0.4",
    "rod_chain:coordinates=joint",
    "rod_chain:coordinates=joint,n=3,mass=2,mass_ratio=0.5,length=0.7,length_ratio=1.5,"
    "gravity=2.5,theta1=0.3,theta2=-1.1,theta3=2.5,omega=0.4",
    "rod_chain:coordinates=joint,n=64,mass_ratio=0.97,length_ratio=1.01,theta=0.4,omega=0.1",
};

DenseMatrix problem_mass_matrix(const Problem& problem, const Vec& q) {
  DenseMatrix M;
  if (const LagrangianSystem* lagrangian = problem.as_lagrangian()) {
    lagrangian->mass_matrix(q, M);
  } else {
    M = problem.mass().asDiagonal();
  }
  return M;
}

// The initial state and random states (angles in [−π, π], rates in [−2, 2]).
std::vector<std::pair<Vec, Vec>> test_states(const Problem& problem) {
  const State initial = problem.initial_state();
  std::vector<std::pair<Vec, Vec>> states = {
      {initial.q, chain_velocity(problem, initial.q, initial.p)}};
  std::mt19937 random(45);
  std::uniform_real_distribution<double> angle(-3.14159, 3.14159), rate(-2, 2);
  for (int k = 0; k < 4; ++k) {
    Vec q(problem.dof()), v(problem.dof());
    for (int i = 0; i < problem.dof(); ++i) q[i] = angle(random), v[i] = rate(random);
    states.emplace_back(q, v);
  }
  return states;
}

double relative_difference(double a, double b) {
  return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300});
}

TEST(MujocoFidelity, MassMatrixPotentialAndKineticEnergyAreTheProblems) {
  for (const auto& spec : kChainSpecs) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    std::string why;
    const auto chain = planar_chain_of(*problem, why);
    ASSERT_TRUE(chain) << why;
    for (const auto& defaults : {false, true}) {
      MujocoChain engine(*chain, {"euler", defaults});
      // The potentials share their zero with every rod hanging down (θ = 0): the problems'
      // constants differ (the pendulum's is ω₀²(1 − cos θ)).
      const Vec down = Vec::Zero(problem->dof());
      engine.set_state(down, down);
      const double engine_down = engine.potential();
      const double problem_down = problem->potential(down);
      for (const auto& [q, v] : test_states(*problem)) {
        engine.set_state(q, v);
        const DenseMatrix M = problem_mass_matrix(*problem, q);
        const DenseMatrix engine_M = engine.mass_matrix_absolute();
        EXPECT_LE((engine_M - M).norm(), 1e-9 * M.norm()) << "M(θ) at θ = " << q.transpose();
        EXPECT_LE(relative_difference(engine.kinetic(), 0.5 * v.dot(M * v)), 1e-9);
        const double V = problem->potential(q) - problem_down;
        const double engine_V = engine.potential() - engine_down;
        // Relative to the potential's scale (|V| alone can pass through 0).
        EXPECT_LE(std::abs(engine_V - V), 1e-9 * std::max(std::abs(problem_down), std::abs(V)));
      }
    }
  }
}

// Runs `spec` on `problem` for `steps` steps of h and returns the final state.
State run_steps(const std::string& spec, const Problem& problem, double h, int steps) {
  const auto method = make_integrator(spec);
  State state = problem.initial_state();
  method->reset(problem, state, h);
  for (int k = 0; k < steps; ++k) {
    const StepStatus status = method->step(problem, state, h);
    EXPECT_TRUE(status.ok) << spec << ": " << status.message;
  }
  return state;
}

// Which textbook scheme each MuJoCo integrator is on the (undamped) pendulum, as geomint methods.
struct Identification {
  std::string engine_spec, geomint_spec, scheme;
};
const std::vector<Identification> kMujocoSchemes = {
    {"mujoco:integrator=euler", "symplectic_euler_a",
     "semi-implicit (symplectic) Euler, kick then drift"},
    {"mujoco:integrator=implicit", "symplectic_euler_a",
     "semi-implicit Euler as well: implicit only in the damping, which the pendulum has none of"},
    {"mujoco:integrator=rk4", "rk4", "classical Runge–Kutta on (θ, θ̇)"},
};

TEST(MujocoIdentification, EachIntegratorIsItsTextbookSchemeToRoundOff) {
  const auto problem = make_problem("pendulum:omega0=2.5,theta0=1.2,v0=0.3");
  constexpr double h = 0.01;
  constexpr int kSteps = 1000;
  for (const auto& [engine_spec, geomint_spec, scheme] : kMujocoSchemes) {
    SCOPED_TRACE(engine_spec + " is " + scheme + " (" + geomint_spec + ")");
    const State engine = run_steps(engine_spec, *problem, h, kSteps);
    const State reference = run_steps(geomint_spec, *problem, h, kSteps);
    EXPECT_LE(std::abs(engine.q[0] - reference.q[0]), 1e-12 * std::abs(reference.q[0]));
    EXPECT_LE(std::abs(engine.p[0] - reference.p[0]), 1e-12 * std::abs(reference.p[0]));
    // ...and not the other scheme: the two differ by far more than round-off.
    const std::string other = geomint_spec == "rk4" ? "symplectic_euler_a" : "rk4";
    const State contrast = run_steps(other, *problem, h, kSteps);
    EXPECT_GT(std::abs(engine.q[0] - contrast.q[0]), 1e-6);
  }
}

// The declared orders, fitted on the pendulum ladder of every method and on the double pendulum.
TEST(MujocoOrders, EachIntegratorHasItsDeclaredOrder) {
  for (const std::string spec : {"mujoco", "mujoco:integrator=rk4", "mujoco:integrator=implicit",
                                 "mujoco:defaults=shipped"}) {
    for (const auto& ladder :
         {verify::pendulum_ladder(), verify::Ladder{"double_pendulum", 0.02, 6, 2.0}}) {
      const verify::CheckResult result = verify::declared_order(spec, ladder);
      EXPECT_TRUE(result.passed) << verify::describe(result);
    }
  }
}

TEST(MujocoFailures, AnUnstableStepEndsTheRunWithMujocosWarning) {
  // h·ω ≈ 25 on the 3-link chain: the explicit step blows up, MuJoCo's bad-qacc check fires.
  const auto problem = make_problem("rod_chain:coordinates=joint,n=3,theta=1.5,gravity=100");
  const auto method = make_integrator("mujoco");
  State state = problem->initial_state();
  method->reset(*problem, state, 2.5);
  StepStatus status;
  for (int k = 0; k < 1000 && status.ok; ++k) status = method->step(*problem, state, 2.5);
  ASSERT_FALSE(status.ok);
  EXPECT_NE(status.reason.find("mujoco_mjWARN_BAD"), std::string::npos) << status.reason;
  EXPECT_NE(status.message.find("MuJoCo warning"), std::string::npos) << status.message;
}

TEST(MujocoApplicability, RefusesOtherProblemsNamingThoseThatApply) {
  const auto method = make_integrator("mujoco");
  for (const std::string spec : {"harmonic", "kepler", "rod_chain"}) {
    const Applicability verdict = applicable(*method, *make_problem(spec));
    EXPECT_FALSE(verdict.ok) << spec;
    EXPECT_NE(verdict.reason.find("rod_chain:coordinates=joint"), std::string::npos)
        << verdict.reason;
  }
  for (const auto& spec : kChainSpecs) EXPECT_TRUE(applicable(*method, *make_problem(spec)).ok);
  EXPECT_EQ(method->provider().label(), "engine:MuJoCo");
}

// ODE keeps the chain in maximal coordinates (one body per rod), so it has no joint-space mass
// matrix: its kinetic energy at random velocities stands in, since the quadratic form determines
// M(θ); the potential as for MuJoCo, and the state survives the trip into the bodies and back.
TEST(OdeFidelity, KineticAndPotentialEnergyAreTheProblemsAndTheStateRoundTrips) {
  for (const auto& spec : kChainSpecs) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    std::string why;
    const auto chain = planar_chain_of(*problem, why);
    ASSERT_TRUE(chain) << why;
    for (const auto& defaults : {false, true}) {
      OdeChain engine(*chain, {"world", defaults});
      const Vec down = Vec::Zero(problem->dof());
      engine.set_state(down, down);
      const double engine_down = engine.potential();
      const double problem_down = problem->potential(down);
      for (const auto& [q, v] : test_states(*problem)) {
        engine.set_state(q, v);
        const DenseMatrix M = problem_mass_matrix(*problem, q);
        EXPECT_LE(relative_difference(engine.kinetic(), 0.5 * v.dot(M * v)), 1e-9);
        const double V = problem->potential(q) - problem_down;
        EXPECT_LE(std::abs(engine.potential() - engine_down - V),
                  1e-9 * std::max(std::abs(problem_down), std::abs(V)));
        Vec q_back, v_back;
        engine.get_state(q_back, v_back);
        EXPECT_LE((q_back - q).norm(), 1e-12 * (1 + q.norm()));
        EXPECT_LE((v_back - v).norm(), 1e-12 * (1 + v.norm()));
      }
    }
  }
}

// ODE's step is no textbook scheme in the problem's coordinates (a constraint solve on the bodies'
// velocities, then a drift of every body), so the pendulum test identifies its order instead:
// halving h roughly halves the error of both steppers (first order).
TEST(OdeIdentification, BothSteppersAreFirstOrderOnThePendulum) {
  const auto problem = make_problem("pendulum:omega0=2.5,theta0=1.2,v0=0.3");
  const double t_end = 1.0;
  const State exact = problem->exact(t_end);
  for (const std::string spec : {"ode:step=world", "ode:step=quick"}) {
    SCOPED_TRACE(spec);
    std::vector<double> errors;
    for (const int steps : {400, 800, 1600}) {
      const State state = run_steps(spec, *problem, t_end / steps, steps);
      errors.push_back(std::abs(state.q[0] - exact.q[0]));
    }
    for (int k = 1; k < 3; ++k) {
      const double order = std::log2(errors[k - 1] / errors[k]);
      EXPECT_GT(order, 0.8) << errors[k - 1] << " " << errors[k];
      EXPECT_LT(order, 1.3) << errors[k - 1] << " " << errors[k];
    }
  }
}

TEST(OdeApplicability, RefusesOtherProblemsNamingThoseThatApply) {
  const auto method = make_integrator("ode:step=quick");
  const Applicability verdict = applicable(*method, *make_problem("kepler"));
  EXPECT_FALSE(verdict.ok);
  EXPECT_NE(verdict.reason.find("rod_chain:coordinates=joint"), std::string::npos)
      << verdict.reason;
  for (const auto& spec : kChainSpecs) EXPECT_TRUE(applicable(*method, *make_problem(spec)).ok);
  EXPECT_EQ(method->provider().label(), "engine:ODE");
}

// Bullet's btMultiBody has no mass-matrix or energy getter: its potential and kinetic energy come
// from its own kinematics (localPosToWorld, the kinetic energy by a central difference along the
// joint rates), against the problem's at the same states.
TEST(BulletFidelity, KineticAndPotentialEnergyAreTheProblems) {
  for (const auto& spec : kChainSpecs) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    std::string why;
    const auto chain = planar_chain_of(*problem, why);
    ASSERT_TRUE(chain) << why;
    BulletChain engine(*chain, {"euler", false});
    const Vec down = Vec::Zero(problem->dof());
    engine.set_state(down, down);
    const double engine_down = engine.potential();
    const double problem_down = problem->potential(down);
    for (const auto& [q, v] : test_states(*problem)) {
      engine.set_state(q, v);
      const DenseMatrix M = problem_mass_matrix(*problem, q);
      EXPECT_LE(relative_difference(engine.kinetic(), 0.5 * v.dot(M * v)), 1e-9);
      const double V = problem->potential(q) - problem_down;
      EXPECT_LE(std::abs(engine.potential() - engine_down - V),
                1e-9 * std::max(std::abs(problem_down), std::abs(V)));
      Vec q_back, v_back;
      engine.get_state(q_back, v_back);
      EXPECT_LE((q_back - q).norm(), 1e-12 * (1 + q.norm()));
      EXPECT_LE((v_back - v).norm(), 1e-12 * (1 + v.norm()));
    }
  }
}

TEST(BulletIdentification, EachIntegratorIsItsTextbookSchemeToRoundOff) {
  const auto problem = make_problem("pendulum:omega0=2.5,theta0=1.2,v0=0.3");
  constexpr double h = 0.01;
  constexpr int kSteps = 1000;
  const std::vector<Identification> schemes = {
      {"bullet:integrator=euler", "symplectic_euler_a",
       "semi-implicit (symplectic) Euler, kick then drift"},
      {"bullet:integrator=rk4", "rk4", "classical Runge–Kutta on (θ, θ̇)"},
  };
  for (const auto& [engine_spec, geomint_spec, scheme] : schemes) {
    SCOPED_TRACE(engine_spec + " is " + scheme + " (" + geomint_spec + ")");
    const State engine = run_steps(engine_spec, *problem, h, kSteps);
    const State reference = run_steps(geomint_spec, *problem, h, kSteps);
    EXPECT_LE(std::abs(engine.q[0] - reference.q[0]), 1e-12 * std::abs(reference.q[0]));
    EXPECT_LE(std::abs(engine.p[0] - reference.p[0]), 1e-12 * std::abs(reference.p[0]));
  }
}

TEST(BulletApplicability, RefusesOtherProblemsNamingThoseThatApply) {
  const auto method = make_integrator("bullet");
  const Applicability verdict = applicable(*method, *make_problem("kepler"));
  EXPECT_FALSE(verdict.ok);
  EXPECT_NE(verdict.reason.find("rod_chain:coordinates=joint"), std::string::npos)
      << verdict.reason;
  for (const auto& spec : kChainSpecs) EXPECT_TRUE(applicable(*method, *make_problem(spec)).ok);
  EXPECT_EQ(method->provider().label(), "engine:Bullet");
}

}  // namespace
}  // namespace geomint::engines
