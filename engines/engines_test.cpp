// The engine methods against the problems they model: the engine's own mass matrix, potential
// and kinetic energy equal the problem's (fidelity); on the pendulum each engine integrator that is
// a textbook scheme reproduces geomint's implementation of that scheme (identification); engine
// warnings end a run as a failed status; refusals name the problems that apply.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <thread>

#include "engines/bullet.hpp"
#include "engines/dart.hpp"
#include "engines/engine_method.hpp"
#include "engines/mujoco.hpp"
#include "engines/ode.hpp"
#include "engines/planar_chain.hpp"
#include "engines/rotor.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"
#include "problems/rigid_body.hpp"
#include "verify/verify.hpp"

namespace geomint::engines {
namespace {

// The contracts of engines/engine_method.hpp hold for every adapter, and refuse a model that
// lacks a member EngineMethod or the fidelity tests use (here: the energies).
struct ChainWithoutEnergies {
  ChainWithoutEnergies(const PlanarChain&, const OdeOptions&) {}
  void set_state(const Vec&, const Vec&) {}
  void get_state(Vec&, Vec&) {}
  StepStatus step(double) { return StepStatus::success(); }
};
static_assert(ChainEngineModel<MujocoChain, MujocoOptions> &&
              ChainEngineModel<OdeChain, OdeOptions> &&
              ChainEngineModel<BulletChain, BulletOptions> &&
              ChainEngineModel<DartChain, DartOptions>);
static_assert(RotorEngineModel<MujocoRotor, MujocoOptions> &&
              RotorEngineModel<OdeRotor, OdeOptions> &&
              RotorEngineModel<BulletRotor, BulletOptions> &&
              RotorEngineModel<DartRotor, DartOptions>);
static_assert(!ChainEngineModel<ChainWithoutEnergies, OdeOptions>);
static_assert(!ChainEngineModel<OdeChain, MujocoOptions>);  // built from its own options only

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

// One engine's model of the chain `spec`, built with each of `options`, against the problem: its
// kinetic and potential energy at each test state (the potential relative to its scale), its
// joint-space mass matrix where it has one (the engines in reduced coordinates; the kinetic
// energy at random velocities stands in for the others, since it determines the matrix), and
// the state's trip into the engine and back.
template <class Engine, class Options>
requires ChainEngineModel<Engine, Options>
void expect_chain_fidelity(const std::string& spec, const std::vector<Options>& options) {
  SCOPED_TRACE(spec);
  const auto problem = make_problem(spec);
  std::string why;
  const auto chain = planar_chain_of(*problem, why);
  ASSERT_TRUE(chain) << why;
  for (const Options& option : options) {
    Engine engine(*chain, option);
    // The potentials share their zero with every rod hanging down (θ = 0): the problems'
    // constants differ (the pendulum's is ω₀²(1 − cos θ)).
    const Vec down = Vec::Zero(problem->dof());
    engine.set_state(down, down);
    const double engine_down = engine.potential();
    const double problem_down = problem->potential(down);
    for (const auto& [q, v] : test_states(*problem)) {
      engine.set_state(q, v);
      const DenseMatrix M = problem_mass_matrix(*problem, q);
      if constexpr (requires { engine.mass_matrix_absolute(); }) {
        EXPECT_LE((engine.mass_matrix_absolute() - M).norm(), 1e-9 * M.norm())
            << "M(θ) at θ = " << q.transpose();
      }
      EXPECT_LE(relative_difference(engine.kinetic(), 0.5 * v.dot(M * v)), 1e-9);
      const double V = problem->potential(q) - problem_down;
      // Relative to the potential's scale (|V| alone can pass through 0).
      EXPECT_LE(std::abs(engine.potential() - engine_down - V),
                1e-9 * std::max(std::abs(problem_down), std::abs(V)));
      Vec q_back, v_back;
      engine.get_state(q_back, v_back);
      EXPECT_LE((q_back - q).norm(), 1e-12 * (1 + q.norm()));
      EXPECT_LE((v_back - v).norm(), 1e-12 * (1 + v.norm()));
    }
  }
}

const std::vector<MujocoOptions> kMujocoOptions = {{"euler", false}, {"euler", true}};

TEST(MujocoFidelity, MassMatrixPotentialAndKineticEnergyAreTheProblems) {
  for (const auto& spec : kChainSpecs) expect_chain_fidelity<MujocoChain>(spec, kMujocoOptions);
}

// Chains longer than MJCF's nesting allows go through URDF: the same mass matrix, energies and
// steps as the problem's, up to the 1024 links of the scaling scene.
const std::vector<std::string> kLongChainSpecs = {
    "rod_chain:coordinates=joint,n=97,mass_ratio=0.99,length_ratio=1.01,theta=0.4,omega=0.1",
    "rod_chain:coordinates=joint,n=256,theta=0.3",
};

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

// MuJoCo 2.2.2's MJCF parser refuses the 97-link chain (its nesting limit), so the adapter writes
// MJCF up to 96 links and URDF beyond; both load, to the 1024 links of results/articulated.
TEST(MujocoChainLength, MjcfToTheNestingLimitUrdfBeyondIt) {
  PlanarChain chain;
  chain.gravity = 1;
  for (int links : {kMaxMjcfChainLinks, kMaxMjcfChainLinks + 1, 1024}) {
    chain.mass.assign(links, 1.0);
    chain.length.assign(links, 1.0);
    const MujocoChain engine(chain, MujocoOptions{});
    const std::string root = links <= kMaxMjcfChainLinks ? "<mujoco" : "<robot";
    EXPECT_EQ(engine.xml().rfind(root, 0), 0u) << links << " links: " << engine.xml().substr(0, 40);
  }
}

TEST(MujocoFidelity, LongChainsThroughUrdfAreTheProblems) {
  for (const auto& spec : kLongChainSpecs) {
    expect_chain_fidelity<MujocoChain>(spec, kMujocoOptions);
  }
}

// MuJoCo's RK4 on a URDF chain follows geomint's RK4: the same model, gravity and integrator.
// Not to round-off: MuJoCo's RK4 runs on (θ, θ̇) and geomint's on (θ, p), which differ at O(h⁵)
// per step once M depends on θ (measured 3.5e-10 relative after 20 steps of h = 0.01); a wrong
// mass, length or gravity moves the state by 1e-3 or more.
TEST(MujocoIdentification, Rk4OnAUrdfChainFollowsGeomintsRk4) {
  const auto problem = make_problem(kLongChainSpecs.front());
  const State engine = run_steps("mujoco:integrator=rk4", *problem, 0.01, 20);
  const State reference = run_steps("rk4", *problem, 0.01, 20);
  EXPECT_LE((engine.q - reference.q).norm(), 1e-8 * reference.q.norm());
  EXPECT_LE((engine.p - reference.p).norm(), 1e-8 * reference.p.norm());
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
    expect_chain_fidelity<OdeChain>(spec,
                                    std::vector<OdeOptions>{{"world", false}, {"world", true}});
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

// Runs `method_spec` `runs` times on each of two threads at once, on a chain and on the heavy top,
// and expects every run to end where one run alone does: no state shared between an engine's
// models across threads (a sweep runs them on its worker threads).
void expect_concurrent_runs_match_one_alone(const std::string& method_spec, int runs) {
  for (const std::string spec : {"rod_chain:coordinates=joint,n=4,theta=0.3", "heavy_top"}) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    const int steps = 50;
    const State alone = run_steps(method_spec, *problem, 0.001, steps);
    std::vector<std::vector<State>> concurrent(2, std::vector<State>(runs));
    std::vector<std::thread> threads;
    for (std::vector<State>& results : concurrent) {
      threads.emplace_back([&problem, &results, &method_spec] {
        for (State& result : results) result = run_steps(method_spec, *problem, 0.001, steps);
      });
    }
    for (std::thread& thread : threads) thread.join();
    for (const std::vector<State>& results : concurrent) {
      for (const State& result : results) {
        EXPECT_EQ(result.q, alone.q);
        EXPECT_EQ(result.p, alone.p);
      }
    }
  }
}

// A sweep steps several ODE worlds at once, one per worker thread. Each world must step on its own
// threading implementation: ODE's default is one process-wide job list without locks, and two
// concurrent dWorldStep calls on it abort the process in ODE's dDebug.
TEST(OdeThreads, WorldsBuiltAndSteppedOnTwoThreadsStepAsTheyDoAlone) {
  expect_concurrent_runs_match_one_alone("ode:step=world", 1000);
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
    expect_chain_fidelity<BulletChain>(spec, std::vector<BulletOptions>{{"euler", false}});
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

// DART's own joint-space mass matrix (Skeleton::getMassMatrix, mapped to absolute angles), its
// potential and kinetic energy equal the problem's, on the chain specs and on a 256-link chain,
// for both defaults= variants; the state survives the trip into the joints and back.
TEST(DartFidelity, MassMatrixPotentialAndKineticEnergyAreTheProblems) {
  std::vector<std::string> specs = kChainSpecs;
  specs.push_back("rod_chain:coordinates=joint,n=256,mass_ratio=0.99,length_ratio=1.002,theta=0.4");
  for (const auto& spec : specs) {
    expect_chain_fidelity<DartChain>(spec,
                                     std::vector<DartOptions>{{"world", false}, {"world", true}});
  }
}

// DART's World::step and the dart::integration classes on the pendulum, each against the geomint
// method of the scheme it is, and not the contrasting one.
TEST(DartIdentification, EachIntegratorIsItsTextbookSchemeToRoundOff) {
  const auto problem = make_problem("pendulum:omega0=2.5,theta0=1.2,v0=0.3");
  constexpr double h = 0.01;
  constexpr int kSteps = 1000;
  const std::vector<Identification> schemes = {
      {"dart:integrator=world", "symplectic_euler_a",
       "semi-implicit (symplectic) Euler, kick then drift: World::step integrates the velocities, "
       "solves the (absent) constraints, then integrates the positions with the new velocities"},
      {"dart:integrator=semi_implicit_euler", "symplectic_euler_a",
       "semi-implicit (symplectic) Euler, kick then drift"},
      // EulerIntegrator::integrate (DART 6.12, its compiled code): integrateConfigs(getGenVels())
      // first, then integrateGenVels(evalGenAccs()) at the moved configuration.
      {"dart:integrator=euler", "symplectic_euler_b",
       "semi-implicit (symplectic) Euler, drift then kick: EulerIntegrator moves the positions "
       "with the old velocities, then the velocities with the accelerations at the new positions "
       "(not explicit Euler)"},
  };
  for (const auto& [engine_spec, geomint_spec, scheme] : schemes) {
    SCOPED_TRACE(engine_spec + " is " + scheme + " (" + geomint_spec + ")");
    const State engine = run_steps(engine_spec, *problem, h, kSteps);
    const State reference = run_steps(geomint_spec, *problem, h, kSteps);
    EXPECT_LE(std::abs(engine.q[0] - reference.q[0]), 1e-12 * std::abs(reference.q[0]));
    EXPECT_LE(std::abs(engine.p[0] - reference.p[0]), 1e-12 * std::abs(reference.p[0]));
    for (const std::string other :
         {"symplectic_euler_a", "symplectic_euler_b", "explicit_euler", "rk4"}) {
      if (other == geomint_spec) continue;
      const State contrast = run_steps(other, *problem, h, kSteps);
      EXPECT_GT(std::abs(engine.q[0] - contrast.q[0]), 1e-6) << "also " << other;
    }
  }
}

// DART 6.12's RK4Integrator::integrate, written out on the pendulum θ̈ = a(θ) = −M⁻¹∇V(θ): the
// stages of classical RK4, except that the fourth is evaluated at θ + (h/2)v₂ + h v₃ (it advances
// the configuration of the third stage by h v₃ without first resetting it to θ).
State dart_rk4_as_shipped(const Problem& problem, double h, int steps) {
  const auto a = [&](double theta) {
    Vec g;
    problem.gradient(Vec::Constant(1, theta), g);
    return -problem.inverse_mass()[0] * g[0];
  };
  State state = problem.initial_state();
  double theta = state.q[0], v = problem.inverse_mass()[0] * state.p[0];
  for (int k = 0; k < steps; ++k) {
    const double v1 = v, a1 = a(theta);
    const double v2 = v + h / 2 * a1, a2 = a(theta + h / 2 * v1);
    const double v3 = v + h / 2 * a2, a3 = a(theta + h / 2 * v2);
    const double v4 = v + h * a3, a4 = a(theta + h / 2 * v2 + h * v3);
    theta += h / 6 * (v1 + 2 * v2 + 2 * v3 + v4);
    v += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  }
  state.q[0] = theta;
  state.p[0] = problem.mass()[0] * v;
  state.t = h * steps;
  return state;
}

// DART's rk4 is that scheme to round-off, not geomint's classical rk4, and it is first order:
// halving h halves its error against the exact pendulum.
TEST(DartIdentification, Rk4IntegratorAsShippedIsAFirstOrderVariantOfRk4) {
  const auto problem = make_problem("pendulum:omega0=2.5,theta0=1.2,v0=0.3");
  constexpr double h = 0.01;
  constexpr int kSteps = 1000;
  const State engine = run_steps("dart:integrator=rk4", *problem, h, kSteps);
  const State written_out = dart_rk4_as_shipped(*problem, h, kSteps);
  EXPECT_LE(std::abs(engine.q[0] - written_out.q[0]), 1e-12 * std::abs(written_out.q[0]));
  EXPECT_LE(std::abs(engine.p[0] - written_out.p[0]), 1e-12 * std::abs(written_out.p[0]));
  const State classical = run_steps("rk4", *problem, h, kSteps);
  EXPECT_GT(std::abs(engine.q[0] - classical.q[0]), 1e-3);
  const double t_end = 1.0;
  const State exact = problem->exact(t_end);
  std::vector<double> errors;
  for (const int steps : {400, 800, 1600}) {
    errors.push_back(std::abs(
        run_steps("dart:integrator=rk4", *problem, t_end / steps, steps).q[0] - exact.q[0]));
  }
  for (int k = 1; k < 3; ++k) {
    const double order = std::log2(errors[k - 1] / errors[k]);
    EXPECT_GT(order, 0.8) << errors[k - 1] << " " << errors[k];
    EXPECT_LT(order, 1.3) << errors[k - 1] << " " << errors[k];
  }
}

// DART's shipped defaults are the values the clean model writes out: the two variants take the
// same steps, bit for bit, on a chain and on a top.
TEST(DartDefaults, ShippedDefaultsTakeTheCleanSteps) {
  for (const std::string problem_spec :
       {"rod_chain:coordinates=joint,n=4,theta=0.3", "heavy_top"}) {
    const auto problem = make_problem(problem_spec);
    for (const std::string integrator : {"world", "rk4"}) {
      SCOPED_TRACE(problem_spec + " with " + integrator);
      const std::string spec = "dart:integrator=" + integrator;
      const State clean = run_steps(spec, *problem, 0.01, 200);
      const State shipped = run_steps(spec + ",defaults=shipped", *problem, 0.01, 200);
      EXPECT_EQ(clean.q, shipped.q);
      EXPECT_EQ(clean.p, shipped.p);
    }
  }
}

// A sweep builds and steps DART skeletons on several worker threads at once: they take the steps
// they take alone (DART keeps no per-process state in a step).
TEST(DartThreads, SkeletonsBuiltAndSteppedOnTwoThreadsStepAsTheyDoAlone) {
  expect_concurrent_runs_match_one_alone("dart", 200);
}

// Every DART step far beyond any stable step on a stiff 3-link chain: the state grows until the
// adapter stops the run as a failed status naming the blow-up, before DART sees a state its joint
// transform asserts on (DART 6.12's assertion in RevoluteJoint aborted the process instead).
TEST(DartFailures, ABlowUpEndsTheRunAsAFailedStatusNotAnAbort) {
  const auto problem = make_problem("rod_chain:coordinates=joint,n=3,theta=1.5,gravity=100");
  for (const std::string& integrator : dart_integrators()) {
    SCOPED_TRACE(integrator);
    const auto method = make_integrator("dart:integrator=" + integrator);
    State state = problem->initial_state();
    constexpr double h = 2.5;
    method->reset(*problem, state, h);
    StepStatus status;
    int steps = 0;
    for (; steps < 10000 && status.ok; ++steps) status = method->step(*problem, state, h);
    ASSERT_FALSE(status.ok) << "still running after " << steps << " steps";
    EXPECT_TRUE(status.reason == "dart_blowup" || status.reason == "dart_nan") << status.reason;
    EXPECT_NE(status.message.find("DART"), std::string::npos) << status.message;
  }
}

TEST(DartApplicability, RefusesOtherProblemsAndChainsLongerThanItBuilds) {
  const auto method = make_integrator("dart");
  const Applicability verdict = applicable(*method, *make_problem("kepler"));
  EXPECT_FALSE(verdict.ok);
  EXPECT_NE(verdict.reason.find("rod_chain:coordinates=joint"), std::string::npos)
      << verdict.reason;
  for (const auto& spec : kChainSpecs) EXPECT_TRUE(applicable(*method, *make_problem(spec)).ok);
  EXPECT_TRUE(applicable(*method, *make_problem("rod_chain:coordinates=joint,n=1024")).ok);
  const Applicability longer =
      applicable(*method, *make_problem("rod_chain:coordinates=joint,n=1025"));
  EXPECT_FALSE(longer.ok);
  EXPECT_NE(longer.reason.find("at most 1024 links"), std::string::npos) << longer.reason;
  EXPECT_EQ(method->provider().label(), "engine:DART");
}

// ----- One rigid body about a fixed point: spherical_pendulum, heavy_top, rigid_body -----

// Every rotor problem at its defaults and at non-unit parameters; the second heavy top has its
// centre off the principal axes (the engines then model it in the rotated principal frame).
const std::vector<std::string> kRotorSpecs = {
    "spherical_pendulum",
    "spherical_pendulum:length=1.7,mass=0.6,gravity=2.5,theta0=2.2,phi0=0.4,theta_dot0=0.3,"
    "phi_dot0=-0.8",
    "spherical_pendulum:coordinates=angles",
    "spherical_pendulum:coordinates=angles,length=1.7,mass=0.6,gravity=2.5,theta0=-0.7,phi0=3,"
    "theta_dot0=0.3,phi_dot0=1.4",
    "heavy_top",
    "heavy_top:I1=2.5,I2=3,I3=4,m=0.8,g=3,chi1=0.2,chi2=-0.1,chi3=0.6,omega1=1.1,omega2=-0.4,"
    "omega3=2,axis1=1,axis2=2,axis3=0.5,angle=0.7",
    "rigid_body",
    "rigid_body:I1=1.5,I2=2.5,I3=3.2,omega1=0.1,omega2=1.3,omega3=-0.2,axis1=1,axis2=2,axis3=0.5,"
    "angle=0.7",
};

// The problem's state at attitude Q and body angular velocity Ω, written from each problem's own
// definition (not through RotorStateMap): q = vec(Q), p_k = d_k Q(Ω × e_k) for the attitude
// problems; the bob at x = Q(0, 0, −L), p = m ẋ for the Cartesian pendulum.
State problem_state_at(const Problem& problem, const Rotor& rotor, const Eigen::Matrix3d& Q,
                       const Eigen::Vector3d& omega) {
  State state;
  if (rotor.kind == Rotor::Kind::kSpherical) {
    const Eigen::Vector3d rod(0, 0, -rotor.length);
    state.q = Q * rod;
    state.p = problem.mass()[0] * (Q * omega.cross(rod));
    return state;
  }
  state.q.resize(9);
  state.p.resize(9);
  for (int k = 0; k < 3; ++k) {
    state.q.segment<3>(3 * k) = Q.col(k);
    state.p.segment<3>(3 * k) = problem.mass()[3 * k] * (Q * omega.cross(Eigen::Vector3d::Unit(k)));
  }
  return state;
}

// The initial state and four random ones: random attitudes and Ω ∈ [−2, 2]³, or for the angle form
// (θ, φ) ∈ [−π, π]² away from the poles and rates in [−2, 2].
std::vector<State> rotor_test_states(const Problem& problem, const Rotor& rotor) {
  std::vector<State> states = {problem.initial_state()};
  std::mt19937 random(45);
  std::uniform_real_distribution<double> unit(-1, 1);
  for (int k = 0; k < 4; ++k) {
    if (rotor.kind == Rotor::Kind::kSphericalAngles) {
      Vec q(2), v(2);
      q << (0.2 + 2.7 * std::abs(unit(random))) * (unit(random) < 0 ? -1 : 1), 3.1 * unit(random);
      v << 2 * unit(random), 2 * unit(random);
      states.push_back({0, q, problem.as_lagrangian()->momentum(q, v)});
      continue;
    }
    const Eigen::Quaterniond attitude =
        Eigen::Quaterniond(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Eigen::Vector3d omega(2 * unit(random), 2 * unit(random), 2 * unit(random));
    states.push_back(problem_state_at(problem, rotor, attitude.toRotationMatrix(), omega));
  }
  return states;
}

// The problem's inertia about the origin in its body frame, J_ij by polarisation of its own kinetic
// energy T = energy − potential at Ω = e_i, e_i + e_j (the pendulum's has no entry about the rod).
Eigen::Matrix3d problem_body_inertia(const Problem& problem, const Rotor& rotor) {
  const auto kinetic = [&](const Eigen::Vector3d& omega) {
    const State state = problem_state_at(problem, rotor, Eigen::Matrix3d::Identity(), omega);
    return problem.energy(state.q, state.p) - problem.potential(state.q);
  };
  Eigen::Matrix3d J;
  for (int i = 0; i < 3; ++i) J(i, i) = 2 * kinetic(Eigen::Vector3d::Unit(i));
  for (int i = 0; i < 3; ++i) {
    for (int j = i + 1; j < 3; ++j) {
      J(i, j) = J(j, i) =
          kinetic(Eigen::Vector3d::Unit(i) + Eigen::Vector3d::Unit(j)) - 0.5 * (J(i, i) + J(j, j));
    }
  }
  return J;
}

double state_distance(const State& a, const State& b) {
  return std::sqrt((a.q - b.q).squaredNorm() + (a.p - b.p).squaredNorm());
}

// For one engine: its kinetic and potential energy equal the problem's to 1e-9 at each test state
// (relative to the energy's scale), and the state survives the trip into the engine and back.
template <class Engine, class Options>
requires RotorEngineModel<Engine, Options>
void check_rotor_engine(const Options& options) {
  for (const auto& spec : kRotorSpecs) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    std::string why;
    const auto rotor = rotor_of(*problem, why);
    ASSERT_TRUE(rotor) << why;
    Engine engine(*rotor, options);
    RotorStateMap map(*rotor);
    for (const State& state : rotor_test_states(*problem, *rotor)) {
      const double V = problem->potential(state.q);
      const double T = problem->energy(state.q, state.p) - V;
      // The potential's scale: m g times the centre's distance from the pivot.
      const double scale = rotor->mass * rotor->gravity * rotor->centre.norm();
      engine.set_state(map.to_principal(map.to_rotor(*problem, state)));
      EXPECT_LE(std::abs(engine.kinetic() - T), 1e-9 * T) << "T at q = " << state.q.transpose();
      EXPECT_LE(std::abs(engine.potential() - V), 1e-9 * std::max(scale, 1e-300))
          << "V at q = " << state.q.transpose();
      State back = state;
      map.to_problem(*problem, map.from_principal(engine.get_state()), back);
      EXPECT_LE(state_distance(back, state), 1e-12 * (1 + state.q.norm() + state.p.norm()))
          << "round trip of q = " << state.q.transpose();
    }
  }
}

// An engine in reduced coordinates: its own mass matrix of the ball (free) joint, mapped from the
// principal frame to the problem's body frame, is the problem's inertia about the origin.
template <class Engine, class Options>
requires RotorEngineModel<Engine, Options>
void expect_rotor_inertia() {
  for (const auto& spec : kRotorSpecs) {
    SCOPED_TRACE(spec);
    const auto problem = make_problem(spec);
    std::string why;
    const auto rotor = rotor_of(*problem, why);
    ASSERT_TRUE(rotor) << why;
    if (rotor->kind == Rotor::Kind::kSphericalAngles) continue;  // the Cartesian form covers it
    Engine engine(*rotor, Options{});
    engine.set_state(RotorState{});
    const Eigen::Matrix3d J = problem_body_inertia(*problem, *rotor);
    const Eigen::Matrix3d engine_J =
        rotor->principal * engine.rotational_mass_matrix() * rotor->principal.transpose();
    EXPECT_LE((engine_J - J).norm(), 1e-9 * J.norm()) << "engine\n"
                                                      << engine_J << "\nproblem\n"
                                                      << J;
  }
}

TEST(RotorFidelity, MujocoInertiaPotentialAndKineticEnergyAreTheProblems) {
  for (const bool shipped : {false, true}) {
    check_rotor_engine<MujocoRotor>(MujocoOptions{"euler", shipped});
  }
  expect_rotor_inertia<MujocoRotor, MujocoOptions>();
}

// ODE and Bullet's btRigidBody are maximal coordinates (no joint-space mass matrix): the kinetic
// energy at random angular velocities stands in, since it determines the inertia.
TEST(RotorFidelity, OdePotentialAndKineticEnergyAreTheProblems) {
  for (const bool shipped : {false, true}) {
    check_rotor_engine<OdeRotor>(OdeOptions{"world", shipped});
  }
}

TEST(RotorFidelity, BulletPotentialAndKineticEnergyAreTheProblems) {
  for (const bool shipped : {false, true}) {
    check_rotor_engine<BulletRotor>(BulletOptions{"euler", shipped, "implicit_body"});
  }
}

TEST(RotorFidelity, DartInertiaPotentialAndKineticEnergyAreTheProblems) {
  for (const bool shipped : {false, true}) {
    check_rotor_engine<DartRotor>(DartOptions{"world", shipped});
  }
  expect_rotor_inertia<DartRotor, DartOptions>();
}

// Every engine method runs every rotor problem; Bullet's options that do not fit a problem refuse
// it, saying why; other problems are refused with the list of those that apply.
TEST(RotorApplicability, EveryEngineRunsTheRotorProblemsAndRefusesTheRest) {
  for (const std::string spec : {"mujoco", "mujoco:integrator=rk4", "mujoco:integrator=implicit",
                                 "ode", "ode:step=quick", "bullet", "dart"}) {
    const auto method = make_integrator(spec);
    for (const auto& problem : kRotorSpecs) {
      const Applicability verdict = applicable(*method, *make_problem(problem));
      EXPECT_TRUE(verdict.ok) << spec << " on " << problem << ": " << verdict.reason;
    }
    const Applicability kepler = applicable(*method, *make_problem("kepler"));
    EXPECT_FALSE(kepler.ok) << spec;
    EXPECT_NE(kepler.reason.find("heavy_top"), std::string::npos) << kepler.reason;
    EXPECT_NE(kepler.reason.find("rod_chain:coordinates=joint"), std::string::npos)
        << kepler.reason;
  }
  const Applicability rk4 =
      applicable(*make_integrator("bullet:integrator=rk4"), *make_problem("rigid_body"));
  EXPECT_FALSE(rk4.ok);
  EXPECT_NE(rk4.reason.find("btRigidBody"), std::string::npos) << rk4.reason;
  EXPECT_TRUE(applicable(*make_integrator("bullet:integrator=rk4"), *make_problem("heavy_top")).ok);
  // Every gyro= value, Bullet's default included, is the btRigidBody's and refused on the top.
  for (const std::string gyro : {"none", "explicit", "implicit_world", "implicit_body"}) {
    const auto method = make_integrator("bullet:gyro=" + gyro);
    EXPECT_TRUE(applicable(*method, *make_problem("rigid_body")).ok) << gyro;
    const Applicability top = applicable(*method, *make_problem("heavy_top"));
    EXPECT_FALSE(top.ok) << gyro;
    EXPECT_NE(top.reason.find("btRigidBody"), std::string::npos) << top.reason;
  }
  // A top whose moments no mass distribution has is refused, saying so.
  const Applicability thin = applicable(*make_integrator("mujoco"),
                                        *make_problem("heavy_top:I1=0.3,I2=0.3,I3=0.5,chi3=1"));
  EXPECT_FALSE(thin.ok);
  EXPECT_NE(thin.reason.find("mass distribution"), std::string::npos) << thin.reason;
}

// Q exp(hΩ̂): the exact rotation by the body angular velocity Ω over h (Rodrigues).
Eigen::Matrix3d rotate_by(const Eigen::Matrix3d& Q, const Eigen::Vector3d& omega, double h) {
  const double angle = omega.norm() * h;
  if (angle == 0) return Q;
  return Q * Eigen::AngleAxisd(angle, omega.normalized()).toRotationMatrix();
}

// The two free-body schemes the engines' steps are, written out: both update Ω first, then turn the
// body by the new Ω over the whole step (the Lie–Euler drift Q⁺ = Q exp(hΩ̂⁺)).
//  explicit: Ω⁺ = Ω + hJ⁻¹(JΩ × Ω), explicit Euler on Euler's equations;
//  implicit: Ω⁺ = Ω − (J + h(Ω̂J − (JΩ)^))⁻¹ h Ω × JΩ, one Newton step of implicit Euler on them
//  from Ω (Bullet's computeGyroscopicImpulseImplicit_Body).
RotorState free_body_step(const RotorState& state, const Eigen::Matrix3d& J, double h,
                          bool implicit) {
  const auto hat = [](const Eigen::Vector3d& v) {
    Eigen::Matrix3d m;
    m << 0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0;
    return m;
  };
  const Eigen::Vector3d& omega = state.omega;
  const Eigen::Vector3d momentum = J * omega;
  Eigen::Vector3d next;
  if (implicit) {
    const Eigen::Matrix3d jacobian = J + h * (hat(omega) * J - hat(momentum));
    next = omega - jacobian.inverse() * (h * omega.cross(momentum));
  } else {
    next = omega + h * J.inverse() * momentum.cross(omega);
  }
  return {rotate_by(state.attitude, next, h), next};
}

// Which scheme each engine's free-body step is: 1000 steps of h = 0.01 on the tennis-racket body
// agree with the written-out scheme to round-off, and differ from the other one.
TEST(RotorIdentification, FreeBodyStepsAreLieEulerWithExplicitOrNewtonImplicitGyroscopicTerm) {
  const auto problem = make_problem("rigid_body");
  std::string why;
  const auto rotor = rotor_of(*problem, why);
  ASSERT_TRUE(rotor) << why;
  constexpr double h = 0.01;
  constexpr int kSteps = 1000;
  const struct {
    std::string engine_spec;
    bool implicit;
  } schemes[] = {{"mujoco:integrator=euler", false},
                 {"bullet:gyro=explicit", false},
                 {"mujoco:integrator=implicit", true},
                 {"bullet:gyro=implicit_body", true},
                 {"bullet:gyro=implicit_world", true},
                 {"dart", false},
                 {"dart:integrator=semi_implicit_euler", false}};
  const State initial = problem->initial_state();
  const auto lie_euler = [&](bool implicit) {
    RotorStateMap map(*rotor);
    RotorState reference = map.to_rotor(*problem, initial);
    for (int k = 0; k < kSteps; ++k) {
      reference = free_body_step(reference, rotor->inertia, h, implicit);
    }
    return problem_state_at(*problem, *rotor, reference.attitude, reference.omega);
  };
  const State explicit_scheme = lie_euler(false), implicit_scheme = lie_euler(true);
  for (const auto& [engine_spec, implicit] : schemes) {
    SCOPED_TRACE(engine_spec + (implicit ? " is Newton-implicit" : " is explicit"));
    const State engine = run_steps(engine_spec, *problem, h, kSteps);
    const State& same = implicit ? implicit_scheme : explicit_scheme;
    const State& other = implicit ? explicit_scheme : implicit_scheme;
    EXPECT_LE(state_distance(engine, same), 1e-11) << "not the scheme it is said to be";
    EXPECT_GT(state_distance(engine, other), 1e-4) << "also the other scheme";
  }
  // ODE's world step is neither.
  for (const std::string spec : {"ode", "ode:step=quick"}) {
    const State engine = run_steps(spec, *problem, h, kSteps);
    EXPECT_GT(state_distance(engine, explicit_scheme), 1e-4) << spec;
    EXPECT_GT(state_distance(engine, implicit_scheme), 1e-4) << spec;
  }
}

// MuJoCo's RK4 on the free body: its body momentum Π(t) is classical RK4 on Euler's equations
// (geomint's quaternion:base=rk4 has the same Π to round-off), but its attitude is not RK4's: the
// quaternion is advanced by the stages' weighted mean velocity, a drift that is second order on
// SO(3), so the spatial angular momentum drifts far more than quaternion:base=rk4's.
TEST(RotorIdentification, MujocoRk4IsClassicalRk4OnEulersEquationsOnly) {
  const auto problem = make_problem("rigid_body");
  constexpr double h = 0.01;
  constexpr int kSteps = 1000;
  const State engine = run_steps("mujoco:integrator=rk4", *problem, h, kSteps);
  const State reference = run_steps("quaternion:base=rk4", *problem, h, kSteps);
  const Eigen::Vector3d engine_pi = rigid_body_body_momentum(engine.q, engine.p);
  const Eigen::Vector3d reference_pi = rigid_body_body_momentum(reference.q, reference.p);
  EXPECT_LE((engine_pi - reference_pi).norm(), 1e-12 * reference_pi.norm());
  const Vec L0 = problem->angular_momentum(problem->initial_state().q, problem->initial_state().p);
  const double engine_drift = (problem->angular_momentum(engine.q, engine.p) - L0).norm();
  const double reference_drift = (problem->angular_momentum(reference.q, reference.p) - L0).norm();
  EXPECT_GT(engine_drift, 1e3 * reference_drift) << engine_drift << " vs " << reference_drift;
}

// Every engine method runs every rotor problem: the rows are ok and, at a small step, follow the
// problem's energy (each engine's step is consistent with the problem's motion: a wrong frame or
// inertia would not be). ODE's clean ball joint lets the pivot drift (ERP = 0), so its spherical
// pendulum gets the looser bound of the run it has.
TEST(RotorRuns, EveryEngineFollowsTheEnergyOfEveryRotorProblem) {
  for (const std::string spec :
       {"mujoco", "mujoco:integrator=rk4", "mujoco:integrator=implicit", "ode", "ode:step=quick",
        "bullet", "bullet:integrator=rk4", "dart", "dart:integrator=rk4"}) {
    const auto method = make_integrator(spec);
    for (const auto& problem_spec : kRotorSpecs) {
      const auto problem = make_problem(problem_spec);
      if (!applicable(*method, *problem).ok) continue;  // bullet:integrator=rk4 on rigid_body
      SCOPED_TRACE(spec + " on " + problem_spec);
      const State start = problem->initial_state();
      const double h = 1e-3;
      const State end = run_steps(spec, *problem, h, 1000);
      ASSERT_TRUE(end.q.allFinite() && end.p.allFinite());
      const double H0 = problem->energy(start.q, start.p);
      const double scale = std::abs(H0) + std::abs(problem->potential(start.q)) + 1e-300;
      const bool ode = method->info().name == "ode";
      EXPECT_LE(std::abs(problem->energy(end.q, end.p) - H0), (ode ? 3e-2 : 1e-2) * scale);
    }
  }
}

// A ball joint far beyond its stable step ends the run with MuJoCo's own warning, as a chain does.
TEST(RotorFailures, AnUnstableTopEndsTheRunWithMujocosWarning) {
  const auto problem = make_problem("heavy_top");
  const auto method = make_integrator("mujoco");
  State state = problem->initial_state();
  method->reset(*problem, state, 2.0);
  StepStatus status;
  for (int k = 0; k < 1000 && status.ok; ++k) status = method->step(*problem, state, 2.0);
  ASSERT_FALSE(status.ok);
  EXPECT_NE(status.reason.find("mujoco_mjWARN_BAD"), std::string::npos) << status.reason;
}

}  // namespace
}  // namespace geomint::engines
