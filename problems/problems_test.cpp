// Registry-driven checks of every problem (docs/DESIGN.md §7): derivatives against finite
// differences, the exact solution against the equations of motion and an independent RK4 run,
// invariants along the exact solution, and validation of spec strings.
#include <fmt/format.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <boost/numeric/odeint/integrate/integrate_adaptive.hpp>
#include <boost/numeric/odeint/stepper/bulirsch_stoer.hpp>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "problems/charged_particle.hpp"
#include "problems/first_order.hpp"
#include "problems/force.hpp"
#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"
#include "problems/rigid_body.hpp"
#include "problems/structures/kepler_orbit.hpp"
#include "problems/structures/time_dependent.hpp"
#include "problems/structures/toda.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace problems_test {
namespace {

// gtest names allow only [A-Za-z0-9_]: "pendulum:theta0=-2.0" -> "pendulum_theta0_m2p0".
std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string out;
  for (char c : info.param) {
    if (std::isalnum(static_cast<unsigned char>(c))) {
      out += c;
    } else if (c == '-') {
      out += 'm';
    } else if (c == '.') {
      out += 'p';
    } else {
      out += '_';
    }
  }
  return out;
}

double inf_norm(const Vec& v) { return v.size() == 0 ? 0.0 : v.lpNorm<Eigen::Infinity>(); }

// Components probed by finite differences: all of them for small systems, an even spread of
// about 48 for large ones so the suite stays fast when large meshes join the registry.
std::vector<int> probe_indices(int n) {
  const int stride = std::max(1, n / 48);
  std::vector<int> indices;
  for (int j = 0; j < n; j += stride) indices.push_back(j);
  return indices;
}

// Natural time unit of a problem: 1/omega_max, else period/2π, else 1.
double time_scale(const Problem& problem) {
  if (problem.has(kOmegaMax)) return 1 / problem.omega_max(problem.initial_state().q);
  if (problem.has(kPeriod)) return problem.period() / (2 * std::numbers::pi);
  return 1.0;
}

// Horizon for checks along the exact solution: a few periods, else the default run length.
double horizon(const Problem& problem) {
  return problem.has(kPeriod) ? 3.3 * problem.period() : problem.default_t_end();
}

// The initial configuration, small deterministic perturbations of it (5% of its size, small
// enough to stay clear of singularities such as Kepler's origin) and points on the exact orbit.
std::vector<Vec> sample_configurations(const Problem& problem) {
  const Vec q0 = problem.initial_state().q;
  std::vector<Vec> points = {q0};
  std::mt19937 generator(12345);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const double amplitude = 0.05 * (inf_norm(q0) > 0 ? inf_norm(q0) : 1.0);
  for (int k = 0; k < 3; ++k) {
    Vec q = q0;
    Vec step(q.size());
    for (int i = 0; i < q.size(); ++i) step[i] = amplitude * uniform(generator);
    // Stay inside the domain of V (an inverted neo-Hookean element has V = +inf): halve the step
    // until the potential is finite.
    while (!std::isfinite(problem.potential(q0 + step))) step /= 2;
    q += step;
    points.push_back(q);
  }
  if (problem.has(kExact)) {
    for (double fraction : {0.13, 0.41, 0.77}) {
      points.push_back(problem.exact(fraction * horizon(problem)).q);
    }
  }
  return points;
}

// Right-hand side of Hamilton's equations (q̇, ṗ) = (M⁻¹p, −∇V(q) + F(q, v, t) − G(q)ᵀλ), the
// constraint force with the exact motion's multipliers λ(t, q, p) on constrained problems; on a
// first-order-only problem y = q and its y' = f(t, y) (p is empty).
Vec hamilton_rhs(const Problem& problem, double t, const Vec& q, const Vec& p) {
  if (const FirstOrderSystem* system = problem.as_first_order()) {
    Vec ydot;
    system->rhs(t, q, ydot);
    return ydot;
  }
  const int n = problem.dof();
  Vec rhs(2 * n);
  if (problem.kind() == ProblemKind::kLagrangian) {
    // (q̇, ṗ) = (v, L_q(q, v)) with M(q)v = p − a(q), from the LagrangianSystem's pieces (the
    // derivatives themselves are checked in problems/lagrangian_test.cpp).
    const LagrangianSystem& system = *problem.as_lagrangian();
    const Vec v = system.velocity(q, p);
    Vec L_q;
    system.lagrangian_q(q, v, L_q);
    rhs << v, L_q;
    return rhs;
  }
  const Vec v = problem.inverse_mass().cwiseProduct(p);
  Vec g;
  problem.gradient(q, g);
  rhs.head(n) = v;
  rhs.tail(n) = -g;
  if (problem.has(kForce)) {
    Vec f;
    force_of(problem).force(q, v, t, f);
    rhs.tail(n) += f;
  }
  if (problem.has(kConstraints)) {
    SparseMatrix G;
    constraints_of(problem).constraint_jacobian(q, G);
    rhs.tail(n) -= G.transpose() * problem.multipliers(t, q, p);
  }
  return rhs;
}

// Numbers compare by value ("0.90" and "0.9"), anything else (choices, flags) as text.
bool same_value(const std::string& a, const std::string& b) {
  char* end_a = nullptr;
  char* end_b = nullptr;
  const double x = std::strtod(a.c_str(), &end_a);
  const double y = std::strtod(b.c_str(), &end_b);
  if (*end_a == '\0' && *end_b == '\0' && end_a != a.c_str() && end_b != b.c_str()) return x == y;
  return a == b;
}

Vec stacked(const State& state) {
  Vec y(state.q.size() + state.p.size());
  y << state.q, state.p;
  return y;
}

class ProblemTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override { problem_ = make_problem(GetParam()); }
  std::unique_ptr<Problem> problem_;
};

// A new structure is one interface with its key plus one offer line in the problem that has it
// (docs/DESIGN.md §2, "Structures"): Problem::as<>() finds it with no change to Problem, other
// structures stay absent, and a key is its address, not its texts (a copy with the same name
// is another structure).
class TimeCrystalStructure {
 public:
  static constexpr StructureKey kStructureKey{"time_crystal", "time crystals", "none built in"};
  virtual ~TimeCrystalStructure() = default;
  virtual double crystal_period() const = 0;
};
struct LookalikeStructure {
  static constexpr StructureKey kStructureKey{"time_crystal", "time crystals", "none built in"};
};

class TimeCrystal final : public Problem, public TimeCrystalStructure {
 public:
  TimeCrystal() { set_mass(Vec::Ones(1)); }
  const void* structure(const StructureKey& key) const override {
    if (const void* offered = offer<TimeCrystalStructure>(key, this)) return offered;
    return Problem::structure(key);
  }
  double crystal_period() const override { return 3.0; }
  State initial_state() const override { return {0.0, Vec::Zero(1), Vec::Zero(1)}; }
  double potential(const Vec&) const override { return 0.0; }
  void gradient(const Vec& q, Vec& g) const override { g = Vec::Zero(q.size()); }
};

TEST(Structures, ANewStructureIsFoundByItsKeyAlone) {
  const TimeCrystal crystal;
  const Problem& problem = crystal;
  ASSERT_EQ(problem.as<TimeCrystalStructure>(), static_cast<const TimeCrystalStructure*>(&crystal));
  EXPECT_EQ(problem.as<TimeCrystalStructure>()->crystal_period(), 3.0);
  EXPECT_EQ(problem.as<LookalikeStructure>(), nullptr);
  EXPECT_EQ(problem.as<FreeRigidBodyStructure>(), nullptr);
  EXPECT_EQ(problem.as<ChargedParticleStructure>(), nullptr);
  EXPECT_EQ(make_problem("pendulum")->as<TimeCrystalStructure>(), nullptr);
}

TEST_P(ProblemTest, SizesMassAndEnergyAreConsistent) {
  const Problem& problem = *problem_;
  if (problem.has(kFirstOrderOnly)) GTEST_SKIP() << "first-order only (problems/first_order_test)";
  const State start = problem.initial_state();
  ASSERT_GT(problem.dof(), 0);
  if (problem.kind() == ProblemKind::kLagrangian) {
    // No constant mass (mass() throws); the energy is H = ½vᵀM(q)v + V with v solved from
    // p = M v + a.
    const LagrangianSystem& system = *problem.as_lagrangian();
    EXPECT_EQ(start.p.size(), problem.dof());
    DenseMatrix M;
    system.mass_matrix(start.q, M);
    Vec a;
    system.gyroscopic(start.q, a);
    const Vec v = M.fullPivLu().solve(start.p - a);
    const double kinetic = 0.5 * v.dot(M * v);
    EXPECT_NEAR(problem.energy(start.q, start.p), kinetic + problem.potential(start.q),
                1e-14 * (kinetic + std::abs(problem.potential(start.q))));
    return;
  }
  EXPECT_EQ(start.q.size(), problem.dof());
  EXPECT_EQ(start.p.size(), problem.dof());
  EXPECT_EQ(problem.inverse_mass().size(), problem.dof());
  EXPECT_EQ(start.t, 0.0);
  for (int i = 0; i < problem.dof(); ++i) {
    EXPECT_GT(problem.mass()[i], 0.0);
    // One rounding in the reciprocal.
    EXPECT_NEAR(problem.mass()[i] * problem.inverse_mass()[i], 1.0, 2 * DBL_EPSILON);
  }
  // Kinetic energy summed independently of Problem::kinetic; a few roundings per term.
  double kinetic = 0;
  for (int i = 0; i < problem.dof(); ++i)
    kinetic += 0.5 * start.p[i] * start.p[i] / problem.mass()[i];
  EXPECT_NEAR(problem.kinetic(start.p), kinetic, 8 * DBL_EPSILON * kinetic);
  EXPECT_NEAR(problem.energy(start.q, start.p), kinetic + problem.potential(start.q),
              8 * DBL_EPSILON * (kinetic + std::abs(problem.potential(start.q))));
  EXPECT_GT(problem.default_dt(), 0.0);
  EXPECT_GT(problem.default_t_end(), problem.default_dt());
  if (problem.has(kPeriod)) {
    EXPECT_GT(problem.period(), 0.0);
  }
  if (!problem.has(kExact)) {
    EXPECT_THROW(problem.exact(1.0), std::logic_error);
  }
}

// A time-dependent H(q, p, t) (problems/structures/time_dependent.hpp): its velocity and momentum
// rate are ∂H/∂p and −∂H/∂q by central differences at several (q, p, t) when it says it is
// Hamiltonian, and at its initial time H is the energy() the time-free pieces give (potential()
// and gradient() are V(q, t₀), which the gradient test above checks).
TEST_P(ProblemTest, TimeDependentHamiltonianMatchesItsEquations) {
  const Problem& problem = *problem_;
  const auto* hamiltonian = problem.as<TimeDependentHamiltonian>();
  if (hamiltonian == nullptr) GTEST_SKIP() << "no time-dependent Hamiltonian";
  const State start = problem.initial_state();
  EXPECT_NEAR(hamiltonian->hamiltonian(start.q, start.p, start.t), problem.energy(start.q, start.p),
              1e-14 * std::max(1.0, std::abs(problem.energy(start.q, start.p))));
  if (!hamiltonian->is_hamiltonian()) GTEST_SKIP() << "a non-Hamiltonian form";
  const int n = problem.dof();
  for (const double t : {0.0, 1.3, 7.9, 22.0}) {
    const Vec q = start.q + 0.7 * Vec::Ones(n), p = start.p - 0.4 * Vec::Ones(n);
    Vec qdot, pdot;
    hamiltonian->velocity(p, t, qdot);
    hamiltonian->momentum_rate(q, p, t, pdot);
    ASSERT_EQ(qdot.size(), n);
    ASSERT_EQ(pdot.size(), n);
    const double h = 1e-5;
    for (int j = 0; j < n; ++j) {
      Vec plus = q, minus = q;
      plus[j] += h, minus[j] -= h;
      const double dH_dq =
          (hamiltonian->hamiltonian(plus, p, t) - hamiltonian->hamiltonian(minus, p, t)) / (2 * h);
      EXPECT_NEAR(pdot[j], -dH_dq, 1e-8 * std::max(1.0, std::abs(dH_dq))) << "t = " << t;
      plus = p, minus = p;
      plus[j] += h, minus[j] -= h;
      const double dH_dp =
          (hamiltonian->hamiltonian(q, plus, t) - hamiltonian->hamiltonian(q, minus, t)) / (2 * h);
      EXPECT_NEAR(qdot[j], dH_dp, 1e-8 * std::max(1.0, std::abs(dH_dp))) << "t = " << t;
    }
  }
}

TEST_P(ProblemTest, GradientMatchesFiniteDifferences) {
  const Problem& problem = *problem_;
  if (problem.has(kFirstOrderOnly)) GTEST_SKIP() << "first-order only: no potential";
  for (const Vec& q : sample_configurations(problem)) {
    Vec g;
    problem.gradient(q, g);
    ASSERT_EQ(g.size(), problem.dof());
    // Step ~ eps^(1/3) relative to the configuration size balances O(h²) truncation against
    // rounding. Allowed: 1e-7 relative (truncation is ~1e-10 here) plus the rounding of the
    // two potential values amplified by 1/h.
    const double h = 1e-5 * std::max(inf_norm(q), 0.1);
    // Richardson extrapolation (4 D(h) - D(2h))/3 cancels the O(h^2) truncation, which for a stiff
    // problem near equilibrium (elastic energy at rest: small gradient, large third derivative)
    // exceeds 1e-7 |g|. Rounding is that of the largest potential value in the stencil.
    for (int j : probe_indices(problem.dof())) {
      Vec plus = q, minus = q, plus2 = q, minus2 = q;
      plus[j] += h;
      minus[j] -= h;
      plus2[j] += 2 * h;
      minus2[j] -= 2 * h;
      const double values[4] = {problem.potential(plus), problem.potential(minus),
                                problem.potential(plus2), problem.potential(minus2)};
      double largest = std::abs(problem.potential(q));
      for (double value : values) largest = std::max(largest, std::abs(value));
      // Relative to the gradient's size over the stencil, not only at q, where it may vanish
      // (a free elastic body at rest: g = 0, V = 0, and only the O(h^4) remainder is left).
      Vec g_far;
      double gradient_size = inf_norm(g);
      for (const Vec* x : {&plus2, &minus2}) {
        problem.gradient(*x, g_far);
        gradient_size = std::max(gradient_size, inf_norm(g_far));
      }
      const double tolerance = 1e-7 * gradient_size + 100 * DBL_EPSILON * largest / h;
      const double difference = (8 * (values[0] - values[1]) - (values[2] - values[3])) / (12 * h);
      EXPECT_NEAR(g[j], difference, tolerance) << "component " << j << " at q = " << q.transpose();
    }
  }
}

// The one-pass V and ∇V (Problem::potential_with_gradient), where a problem has it, are those of
// potential() and gradient() bit for bit, so a method may use either; where it has none it says so
// and leaves its outputs alone.
TEST_P(ProblemTest, PotentialWithGradientHasTheBitsOfTheTwo) {
  const Problem& problem = *problem_;
  if (problem.has(kFirstOrderOnly)) GTEST_SKIP() << "first-order only: no potential";
  for (const Vec& q : sample_configurations(problem)) {
    Vec g = Vec::Constant(3, 7.0);
    double V = 7.0;
    if (!problem.potential_with_gradient(q, g, V)) {
      EXPECT_EQ(g, Vec::Constant(3, 7.0));
      EXPECT_EQ(V, 7.0);
      continue;
    }
    Vec g_alone;
    problem.gradient(q, g_alone);
    const double V_alone = problem.potential(q);
    EXPECT_TRUE(V == V_alone || (std::isnan(V) && std::isnan(V_alone))) << V << " " << V_alone;
    ASSERT_EQ(g.size(), g_alone.size());
    EXPECT_EQ(std::memcmp(g.data(), g_alone.data(), sizeof(double) * g.size()), 0);
  }
}

TEST_P(ProblemTest, HessianMatchesFiniteDifferencesAndIsSymmetric) {
  const Problem& problem = *problem_;
  if (!problem.has(kHessian)) GTEST_SKIP() << "no Hessian declared";
  const int n = problem.dof();
  for (const Vec& q : sample_configurations(problem)) {
    SparseMatrix H;
    problem.hessian(q, H);
    ASSERT_EQ(H.rows(), n);
    ASSERT_EQ(H.cols(), n);
    const Eigen::MatrixXd dense(H);
    const double size = dense.cwiseAbs().maxCoeff();
    // Symmetry should hold to rounding of the assembly, not only approximately.
    EXPECT_LE((dense - dense.transpose()).cwiseAbs().maxCoeff(), 4 * DBL_EPSILON * size);
    Vec g;
    problem.gradient(q, g);
    const double h = 1e-5 * std::max(inf_norm(q), 0.1);
    // Same reasoning as for the gradient, one derivative higher: 1e-6 relative plus rounding.
    const double tolerance = 1e-6 * size + 100 * DBL_EPSILON * inf_norm(g) / h;
    for (int j : probe_indices(n)) {
      Vec plus = q, minus = q, plus2 = q, minus2 = q;
      plus[j] += h;
      minus[j] -= h;
      plus2[j] += 2 * h;
      minus2[j] -= 2 * h;
      Vec g_plus, g_minus, g_plus2, g_minus2;
      problem.gradient(plus, g_plus);
      problem.gradient(minus, g_minus);
      problem.gradient(plus2, g_plus2);
      problem.gradient(minus2, g_minus2);
      // Richardson-extrapolated, as for the gradient.
      const Vec column = (8 * (g_plus - g_minus) - (g_plus2 - g_minus2)) / (12 * h);
      for (int i = 0; i < n; ++i) {
        EXPECT_NEAR(dense(i, j), column[i], tolerance) << "entry (" << i << ", " << j << ")";
      }
    }
  }
}

TEST_P(ProblemTest, ExactStartsAtInitialState) {
  const Problem& problem = *problem_;
  if (!problem.has(kExact)) GTEST_SKIP() << "no exact solution declared";
  const State start = problem.initial_state();
  const State exact = problem.exact(0.0);
  EXPECT_EQ(exact.t, 0.0);
  ASSERT_EQ(exact.q.size(), start.q.size());
  ASSERT_EQ(exact.p.size(), start.p.size());
  // Special functions (elliptic, Kepler's equation) reproduce the start to a few ulps; 1e-13
  // leaves room for the conditioning near a separatrix but catches a wrong phase or branch.
  const double q_scale = std::max(inf_norm(start.q), 1.0);
  const double p_scale = std::max(inf_norm(start.p), inf_norm(start.q) / time_scale(problem));
  EXPECT_LE(inf_norm(exact.q - start.q), 1e-13 * q_scale) << exact.q.transpose();
  EXPECT_LE(inf_norm(exact.p - start.p), 1e-13 * p_scale) << exact.p.transpose();
}

TEST_P(ProblemTest, ExactSatisfiesEquationsOfMotion) {
  const Problem& problem = *problem_;
  if (!problem.has(kExact)) GTEST_SKIP() << "no exact solution declared";
  // Central differences in t with h = 1e-4 of the time unit: truncation ~1e-9 and rounding
  // ~1e-12 relative to the rate of change, well inside 1e-6.
  const double h = 1e-4 * time_scale(problem);
  const double step = horizon(problem) / 23;
  for (int k = 0; k <= 23; ++k) {
    const double t = k * step + 0.1 * step;
    const State at = problem.exact(t);
    const Vec rate = (stacked(problem.exact(t + h)) - stacked(problem.exact(t - h))) / (2 * h);
    const Vec rhs = hamilton_rhs(problem, t, at.q, at.p);
    EXPECT_LE(inf_norm(rate - rhs), 1e-6 * inf_norm(rhs))
        << "t = " << t << "\n difference quotient: " << rate.transpose()
        << "\n equations of motion: " << rhs.transpose();
  }
}

TEST_P(ProblemTest, ExactMatchesIndependentRk4) {
  const Problem& problem = *problem_;
  if (!problem.has(kExact)) GTEST_SKIP() << "no exact solution declared";
  // Past one full period so that phase, period and any argument reduction are all exercised.
  const double t_end =
      problem.has(kPeriod) ? 1.3 * problem.period() : std::min(problem.default_t_end(), 20.0);
  // h·omega_max = 0.002: RK4's global error ~ (h omega)^4 ~ 1e-11, far below the 1e-8 allowed.
  const long steps = std::lround(std::ceil(t_end / (0.002 * time_scale(problem))));
  if (steps > 10'000'000) GTEST_SKIP() << "too stiff for a quick RK4 reference (" << steps << ")";
  const double h = t_end / static_cast<double>(steps);
  const int n = problem.dof();
  const State start = problem.initial_state();
  Vec y = stacked(start);
  // p has n entries, or none on a first-order-only problem.
  const int np = static_cast<int>(start.p.size());
  const auto f = [&](double t, const Vec& z) {
    return hamilton_rhs(problem, t, z.head(n), z.tail(np));
  };
  for (long k = 0; k < steps; ++k) {
    const double t = static_cast<double>(k) * h;
    const Vec k1 = f(t, y);
    const Vec k2 = f(t + h / 2, y + h / 2 * k1);
    const Vec k3 = f(t + h / 2, y + h / 2 * k2);
    const Vec k4 = f(t + h, y + h * k3);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  const State exact = problem.exact(t_end);
  const double q_scale = std::max(inf_norm(start.q), inf_norm(exact.q));
  const double p_scale = std::max(inf_norm(start.p), inf_norm(exact.p));
  EXPECT_LE(inf_norm(y.head(n) - exact.q), 1e-8 * q_scale)
      << "rk4 " << y.head(n).transpose() << " exact " << exact.q.transpose();
  EXPECT_LE(inf_norm(y.tail(np) - exact.p), 1e-8 * p_scale)
      << "rk4 " << y.tail(np).transpose() << " exact " << exact.p.transpose();
}

TEST_P(ProblemTest, InvariantsAreConstantAlongExact) {
  const Problem& problem = *problem_;
  if (!problem.has(kExact)) GTEST_SKIP() << "no exact solution declared";
  const State start = problem.initial_state();
  // A first-order-only problem has no p, energy or momenta (p is empty: kinetic() and the
  // momentum scale would read past it); its Casimir, where it has one, is checked below.
  const bool mechanical = !problem.has(kFirstOrderOnly);
  const double energy0 = mechanical ? problem.energy(start.q, start.p) : 0.0;
  // Relative to the sizes of the two energy terms, which cancel for bound orbits (Kepler).
  // kinetic(p) reads the constant mass, which a non-separable problem does not have (kinetic()
  // throws; its p = m v + qA of an electron is 1e-24): there the kinetic energy is H − V.
  const double kinetic0 = !mechanical ? 0.0
                          : problem.kind() == ProblemKind::kLagrangian
                              ? energy0 - problem.potential(start.q)
                              : problem.kinetic(start.p);
  const double energy_scale =
      mechanical ? std::max(kinetic0 + std::abs(problem.potential(start.q)), DBL_MIN) : 1.0;
  const double momentum_scale =
      mechanical ? std::max(inf_norm(start.q) * inf_norm(start.p), DBL_MIN) : 1.0;
  std::vector<double> times;
  for (int k = 0; k <= 200; ++k) times.push_back(k * horizon(problem) / 200);
  // A late time checks that long runs do not lose accuracy (argument reduction).
  if (problem.has(kPeriod)) times.push_back(1000.37 * problem.period());
  // Round-off level: a few dozen ulps of the state feed each invariant.
  constexpr double kTolerance = 1e-12;
  for (double t : times) {
    const State at = problem.exact(t);
    if (problem.has(kCasimir)) {
      const double casimir0 = problem.casimir(start.q, start.p);
      EXPECT_LE(std::abs(problem.casimir(at.q, at.p) - casimir0), kTolerance * std::abs(casimir0))
          << "Casimir at t = " << t;
    }
    if (!mechanical) continue;
    if (!problem.has(kForce)) {
      EXPECT_LE(std::abs(problem.energy(at.q, at.p) - energy0), kTolerance * energy_scale)
          << "energy at t = " << t;
    }
    if (problem.has(kAngularMomentum)) {
      const Vec drift =
          problem.angular_momentum(at.q, at.p) - problem.angular_momentum(start.q, start.p);
      EXPECT_LE(inf_norm(drift), kTolerance * momentum_scale) << "angular momentum at t = " << t;
    }
    if (problem.has(kLinearMomentum)) {
      const Vec drift =
          problem.linear_momentum(at.q, at.p) - problem.linear_momentum(start.q, start.p);
      EXPECT_LE(inf_norm(drift), kTolerance * std::max(inf_norm(start.p), DBL_MIN))
          << "linear momentum at t = " << t;
    }
  }
}

TEST_P(ProblemTest, ExactReturnsAfterPeriod) {
  const Problem& problem = *problem_;
  if (!problem.has(kPeriod) || !problem.has(kExact)) GTEST_SKIP() << "no period or exact solution";
  const double period = problem.period();
  // 1e-10: the phase error of one period is rounding of T times the rates.
  for (double t : {0.0, 0.37 * period, 2.9 * period}) {
    const Vec now = stacked(problem.exact(t));
    Vec change = stacked(problem.exact(t + period)) - now;
    // An angle may come back whole turns further on (a rotating pendulum): only q mod 2π returns.
    for (int i = 0; i < problem.dof(); ++i) {
      change[i] -= 2 * std::numbers::pi * std::round(change[i] / (2 * std::numbers::pi));
    }
    EXPECT_LE(inf_norm(change), 1e-10 * std::max(inf_norm(now), 1.0)) << "t = " << t;
  }
}

TEST_P(ProblemTest, OmegaMaxBoundsLinearisedFrequency) {
  const Problem& problem = *problem_;
  if (!problem.has(kOmegaMax)) GTEST_SKIP() << "no omega_max declared";
  if (!problem.has(kHessian) || problem.dof() > 200) GTEST_SKIP() << "needs a small Hessian";
  // omega_max may be a bound over the motion rather than over all of configuration space
  // (Kepler's perihelion rate), so it is checked on states the motion visits.
  std::vector<Vec> visited = {problem.initial_state().q};
  if (problem.has(kExact)) {
    for (int k = 1; k <= 40; ++k) visited.push_back(problem.exact(k * horizon(problem) / 40).q);
  }
  for (const Vec& q : visited) {
    const double omega = problem.omega_max(q);
    EXPECT_TRUE(std::isfinite(omega) && omega > 0) << omega;
    SparseMatrix H;
    problem.hessian(q, H);
    // Frequencies are square roots of the positive eigenvalues of M^(-1/2) H M^(-1/2).
    const Vec scale = problem.inverse_mass().cwiseSqrt();
    const Eigen::MatrixXd scaled = scale.asDiagonal() * Eigen::MatrixXd(H) * scale.asDiagonal();
    const double top =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(scaled).eigenvalues().maxCoeff();
    EXPECT_GE(omega * (1 + 1e-12), std::sqrt(std::max(top, 0.0))) << "q = " << q.transpose();
  }
}

TEST_P(ProblemTest, CanonicalSpecIsSortedCompleteAndStable) {
  const Problem& problem = *problem_;
  const std::string& canonical = problem.spec();
  const Spec parsed = Spec::parse(canonical);
  EXPECT_EQ(parsed.name, problem.name());
  // Keys in the string itself must be sorted (Spec::parse sorts them anyway).
  std::vector<std::string> keys;
  const auto colon = canonical.find(':');
  for (size_t start = colon; start != std::string::npos;) {
    const auto end = canonical.find('=', start);
    keys.push_back(canonical.substr(start + 1, end - start - 1));
    start = canonical.find(',', end);
  }
  EXPECT_TRUE(std::is_sorted(keys.begin(), keys.end())) << canonical;
  // Every user-given value survives; defaults are filled for the rest.
  for (const auto& [key, value] : Spec::parse(GetParam()).values) {
    ASSERT_TRUE(parsed.values.count(key)) << key << " missing from " << canonical;
    EXPECT_TRUE(same_value(parsed.values.at(key), value))
        << key << ": " << value << " became " << parsed.values.at(key);
  }
  const auto again = make_problem(canonical);
  EXPECT_EQ(again->spec(), canonical);
  EXPECT_EQ(stacked(again->initial_state()), stacked(problem.initial_state()));
}

TEST_P(ProblemTest, RejectsUnknownKeysAndMalformedValues) {
  const std::string name = problem_->name();
  // The message names the unknown key and lists the valid ones — of this parameter set, since
  // some keys exist only for some values of others (rod_chain's theta<i> for i <= n).
  std::vector<std::string> named = {"no_such_key"};
  for (const auto& [key, value] : Spec::parse(problem_->spec()).values) named.push_back(key);
  const std::string with_unknown_key =
      problem_->spec() + (problem_->spec() == name ? ":" : ",") + "no_such_key=1";
  EXPECT_TRUE(test::input_error_names(make_problem, with_unknown_key, named));
  for (const auto& [key, value] : Spec::parse(problem_->spec()).values) {
    EXPECT_TRUE(test::input_error_names(make_problem, name + ":" + key + "=not_a_number", key));
  }
}

// The kind and structure queries of Problem (problems/problem.hpp) replace dynamic_casts: a class
// that derives from an interface but forgets to return `this` from its query would silently lose
// every method that needs it. Each registered problem's answers are checked against the casts.
TEST_P(ProblemTest, KindQueriesAgreeWithTheInterfacesTheClassDerivesFrom) {
  const Problem& problem = *problem_;
  EXPECT_EQ(problem.as_lagrangian(), dynamic_cast<const LagrangianSystem*>(&problem));
  EXPECT_EQ(problem.as<FreeRigidBodyStructure>(),
            dynamic_cast<const FreeRigidBodyStructure*>(&problem));
  EXPECT_EQ(problem.as<AttitudeStructure>(), dynamic_cast<const AttitudeStructure*>(&problem));
  EXPECT_EQ(problem.as<ChargedParticleStructure>(),
            dynamic_cast<const ChargedParticleStructure*>(&problem));
  EXPECT_EQ(problem.as<TodaStructure>(), dynamic_cast<const TodaStructure*>(&problem));
  EXPECT_EQ(problem.as<TimeDependentHamiltonian>(),
            dynamic_cast<const TimeDependentHamiltonian*>(&problem));
  // Instance-level: nbody offers the Kepler orbit only with two bodies.
  if (const auto* orbit = problem.as<KeplerOrbitStructure>()) {
    EXPECT_EQ(orbit, dynamic_cast<const KeplerOrbitStructure*>(&problem));
  }
  // Constraints are instance-level (elastic_bar has them only with clamp=constraint|pin): when
  // present they are the class's own interface; a class that derives from it and declines it has
  // none (m = 0), so one that forgets to return `this` fails here; the query alone sets the bits.
  const HolonomicConstraints* constraints = problem.as_constrained();
  const auto* derived = dynamic_cast<const HolonomicConstraints*>(&problem);
  if (constraints != nullptr) {
    EXPECT_EQ(constraints, derived);
  } else if (derived != nullptr) {
    EXPECT_EQ(derived->constraint_count(), 0) << "derives from HolonomicConstraints, returns none";
  }
  EXPECT_EQ(problem.has(kConstraints), constraints != nullptr);
  EXPECT_EQ(problem.has(kTimeDependentConstraints),
            constraints != nullptr && constraints->time_dependent());
  // The force, instance-level like the constraints: when offered it is the class's own
  // interface; a class that derives from it and declines it (an undamped spring net) has F = 0 at
  // the start, so one that forgets to return `this` on a forced instance fails here. kForce and
  // kForceJacobian come from the query alone, and a force offers force_jacobian_v exactly when
  // has_force_jacobian() says so (one that computes it without saying so would be lost).
  const NonConservativeForce* forced = problem.as_forced();
  const auto* force_class = dynamic_cast<const NonConservativeForce*>(&problem);
  const State start = problem.initial_state();
  // The velocity by kind: M⁻¹p, ∂H/∂p of the LagrangianSystem, or none (a first-order problem).
  const Vec v0 = problem.kind() == ProblemKind::kSeparable
                     ? Vec(problem.inverse_mass().cwiseProduct(start.p))
                 : problem.kind() == ProblemKind::kLagrangian
                     ? problem.as_lagrangian()->velocity(start.q, start.p)
                     : Vec(Vec::Zero(problem.dof()));
  if (forced != nullptr) {
    EXPECT_EQ(forced, force_class);
    SparseMatrix C;
    if (forced->has_force_jacobian()) {
      forced->force_jacobian_v(start.q, v0, start.t, C);
      EXPECT_EQ(C.rows(), problem.dof());
      EXPECT_EQ(C.cols(), problem.dof());
    } else {
      EXPECT_THROW(forced->force_jacobian_v(start.q, v0, start.t, C), std::logic_error);
    }
  } else if (force_class != nullptr) {
    Vec f;
    force_class->force(start.q, v0, start.t, f);
    EXPECT_EQ(f.cwiseAbs().maxCoeff(), 0.0) << "derives from NonConservativeForce, returns none";
  }
  EXPECT_EQ(problem.has(kForce), forced != nullptr);
  EXPECT_EQ(problem.has(kForceJacobian), forced != nullptr && forced->has_force_jacobian());
  EXPECT_EQ((problem.capabilities() & kForce) != 0, forced != nullptr);
  EXPECT_EQ((problem.capabilities() & kForceJacobian) != 0,
            forced != nullptr && forced->has_force_jacobian());
  // The first-order kind: the query is the class's own interface, and alone sets the bit.
  EXPECT_EQ(problem.as_first_order(), dynamic_cast<const FirstOrderSystem*>(&problem));
  EXPECT_EQ(problem.has(kFirstOrderOnly), problem.as_first_order() != nullptr);
  EXPECT_EQ((problem.capabilities() & kFirstOrderOnly) != 0, problem.as_first_order() != nullptr);
  const ProblemKind expected = problem.as_first_order()  ? ProblemKind::kFirstOrder
                               : problem.as_lagrangian() ? ProblemKind::kLagrangian
                                                         : ProblemKind::kSeparable;
  EXPECT_EQ(problem.kind(), expected) << kind_name(problem.kind());
}

// The error of a call that must throw std::logic_error, or "" when it does not throw.
std::string logic_error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const std::logic_error& error) {
    return error.what();
  }
  return "";
}

// A constant mass exists only for the separable kind: on a Lagrangian problem (M(q)) and a
// first-order one (no mass) mass(), inverse_mass() and kinetic() throw, naming problem and kind,
// instead of answering with a placeholder of ones; dof() is set all the same.
TEST_P(ProblemTest, OnlyTheSeparableKindHasAConstantMass) {
  const Problem& problem = *problem_;
  const State start = problem.initial_state();
  ASSERT_GT(problem.dof(), 0);
  EXPECT_EQ(start.q.size(), problem.dof());
  if (problem.kind() == ProblemKind::kSeparable) {
    EXPECT_EQ(problem.mass().size(), problem.dof());
    EXPECT_EQ(problem.inverse_mass().size(), problem.dof());
    EXPECT_NO_THROW(problem.kinetic(start.p));
    return;
  }
  const std::string expected = fmt::format("problem '{}' is of kind {}: it has no constant mass",
                                           problem.name(), kind_name(problem.kind()));
  const Vec p = Vec::Ones(problem.dof());
  for (const auto& [what, call] : std::vector<std::pair<std::string, std::function<void()>>>{
           {"mass()", [&] { (void)problem.mass(); }},
           {"inverse_mass()", [&] { (void)problem.inverse_mass(); }},
           {"kinetic(p)", [&] { (void)problem.kinetic(p); }}}) {
    EXPECT_NE(logic_error_of(call).find(expected), std::string::npos)
        << what << " on " << problem.spec() << ": '" << logic_error_of(call) << "'";
  }
}

INSTANTIATE_TEST_SUITE_P(Registry, ProblemTest, ::testing::ValuesIn(problem_test_specs()),
                         test_name);

// ---------------------------------------------------------------------------------------------
// Every closed form on every branch of its parameters, against two library integrators that
// share no code with it or with each other: GSL's Prince–Dormand 8(9) and Boost.Odeint's
// Bulirsch–Stoer extrapolation, both at rtol 1e-13. The registry's variants are joined by the
// branches a closed form switches between (libration and rotation of the pendulum on both sides
// of the separatrix and with whole turns in θ0, Kepler at e ≥ 0.9, the three damping regimes and
// their borders, resonance), and the period is checked as a return time that no shorter
// twelfth of it is.

// The branches beyond the registry's variants, per problem with an exact solution. A problem
// with an exact solution and no entry here fails ExactSolutionBranches.EveryExactProblemIsListed.
const std::map<std::string, std::vector<std::string>>& exact_branches() {
  static const std::map<std::string, std::vector<std::string>> branches = {
      {"harmonic", {"omega=7,mass=0.3,q0=-2,v0=5"}},
      {"pendulum",
       {"theta0=0.1,omega0=2.5",          // small libration
        "theta0=3.1",                     // libration, k' = 0.02
        "theta0=0,v0=1.98",               // libration from the bottom, just below
        "theta0=0,v0=2.02",               // rotation just above the separatrix
        "theta0=0,v0=-2.02",              // the same, turning the other way
        "theta0=-2.5,v0=1.5,omega0=0.8",  // rotation from a high start
        "theta0=0.3,v0=-3,omega0=1.5",    // rotation, negative direction
        "theta0=12.9,v0=0.4",             // libration about 4π (turns offset)
        "theta0=-9.5,v0=-4"}},            // rotation with a turns offset
      {"kepler", {"e=0.3", "e=0.95"}},
      // A parallel E that reverses the motion along B; a strong perpendicular E (drift faster
      // than the gyration speed, a trochoid with loops removed).
      {"charged_particle", {"Ez=-0.3,vz=0.6", "mass=3,charge=2,B=0.5,Ex=1.2,vx=-0.7,vy=0.2"}},
      {"damped_oscillator",
       {"zeta=0,omega=1.7,q0=0.3,v0=-1",               // no damping (no force)
        "zeta=0.999999,omega=2",                       // just underdamped
        "zeta=1.000001,omega=2",                       // just overdamped (μt < 1 for long)
        "zeta=1,omega=1.5,q0=0,v0=2",                  // critical from the equilibrium
        "zeta=0,omega=2,drive=0.7,drive_omega=2",      // undamped resonance: secular growth
        "zeta=0.5,omega=2,drive=1.5,drive_omega=2",    // damped, driven at ω
        "zeta=3,omega=1,drive=0.4,drive_omega=0.3"}},  // overdamped and driven
      {"spring_chain",
       {"n=4,ends=free,velocity=0.5,mode=3", "n=5,init=node,node=5,ends=free",
        "n=7,init=node,node=7,ends=fixed_free,stiffness=2.5"}},
      {"stiff_spring", {"ratio=1,stretch=0.3"}},
      // The step load on a finer rod of either mass; a free vibration in the highest mode.
      {"elastic_rod",
       {"elements=16,young=4,load=2", "mass=consistent,elements=16,density=0.5,load=-0.3",
        "elements=3,load=0,amplitude=0.2,mode=3"}},
      {"cartesian_pendulum", {"theta0=3.0,length=1.5", "theta0=0.2,v0=-2.5,length=0.8,gravity=2"}},
      {"spherical_pendulum", {"theta0=1.3,length=0.6,gravity=9.81"}},
      // I = (1, 2, 2.5): 2E·I2 − |Π|² = ω1² − 1.25ω3², so ω3 = 0.1/√1.25 ≈ 0.08944 is the
      // separatrix at ω1 = 0.1.
      {"rigid_body_euler",
       {"I1=1,I2=2,I3=2.5,omega1=0.1,omega2=1,omega3=0.089",     // just inside: about axis 1
        "I1=1,I2=2,I3=2.5,omega1=0.1,omega2=1,omega3=0.0899",    // just outside: about axis 3
        "I1=1,I2=2,I3=2.5,omega1=1,omega2=0.2,omega3=-0.1",      // far from it, about axis 1
        "I1=2.5,I2=2,I3=1,omega1=0.1,omega2=-0.5,omega3=0.9"}},  // moments in falling order
  };
  return branches;
}

// The registry's default and variants of `entry` plus its listed branches.
std::vector<std::string> branch_specs(const ProblemEntry& entry) {
  std::vector<std::string> specs = {entry.name};
  for (const auto& variant : entry.variants) specs.push_back(entry.name + ":" + variant);
  const auto listed = exact_branches().find(entry.name);
  if (listed != exact_branches().end()) {
    for (const auto& branch : listed->second) specs.push_back(entry.name + ":" + branch);
  }
  return specs;
}

// The states at `times` (increasing, > 0) of Hamilton's equations from the initial state.
using Trajectory = std::vector<Vec>;
using Rhs = std::function<Vec(double, const Vec&)>;

struct GslSystem {
  const Rhs* rhs;
  int dimension;
};

Trajectory integrate_gsl_rk8pd(const Rhs& rhs, const Vec& y0, const std::vector<double>& times,
                               double rtol, double atol) {
  GslSystem data{&rhs, static_cast<int>(y0.size())};
  const auto function = [](double t, const double y[], double dydt[], void* params) -> int {
    const auto* system = static_cast<GslSystem*>(params);
    const Vec rate = (*system->rhs)(t, Eigen::Map<const Vec>(y, system->dimension));
    std::copy(rate.data(), rate.data() + rate.size(), dydt);
    return GSL_SUCCESS;
  };
  gsl_odeiv2_system system{function, nullptr, static_cast<size_t>(y0.size()), &data};
  gsl_odeiv2_driver* driver =
      gsl_odeiv2_driver_alloc_y_new(&system, gsl_odeiv2_step_rk8pd, 1e-6, atol, rtol);
  gsl_odeiv2_driver_set_nmax(driver, 100'000'000);
  Vec y = y0;
  double t = 0;
  Trajectory out;
  for (double stop : times) {
    const int status = gsl_odeiv2_driver_apply(driver, &t, stop, y.data());
    EXPECT_EQ(status, GSL_SUCCESS) << "gsl_rk8pd at t = " << t;
    out.push_back(y);
  }
  gsl_odeiv2_driver_free(driver);
  return out;
}

Trajectory integrate_odeint_bulirsch_stoer(const Rhs& rhs, const Vec& y0,
                                           const std::vector<double>& times, double rtol,
                                           double atol) {
  using Buffer = std::vector<double>;
  namespace odeint = boost::numeric::odeint;
  const auto system = [&](const Buffer& y, Buffer& dydt, double t) {
    const Vec rate = rhs(t, Eigen::Map<const Vec>(y.data(), static_cast<long>(y.size())));
    dydt.assign(rate.data(), rate.data() + rate.size());
  };
  odeint::bulirsch_stoer<Buffer> stepper(atol, rtol);
  Buffer y(y0.data(), y0.data() + y0.size());
  double t = 0;
  Trajectory out;
  for (double stop : times) {
    odeint::integrate_adaptive(stepper, system, y, t, stop, (stop - t) / 100);
    t = stop;
    out.push_back(Eigen::Map<const Vec>(y.data(), static_cast<long>(y.size())));
  }
  return out;
}

TEST(ExactSolutionBranches, EveryExactProblemIsListed) {
  for (const auto& entry : problem_registry()) {
    if (!entry.builtin) continue;
    bool exact = false;
    for (const auto& spec : branch_specs(entry)) exact = exact || make_problem(spec)->has(kExact);
    EXPECT_TRUE(!exact || exact_branches().count(entry.name))
        << entry.name << " has an exact solution: list its branches in exact_branches()";
  }
  for (const auto& [name, branches] : exact_branches()) {
    for (const auto& branch : branches) {
      EXPECT_TRUE(make_problem(name + ":" + branch)->has(kExact)) << name << ":" << branch;
    }
  }
}

// Closed form and period against both integrators, on each branch of each problem.
class ExactBranch : public ::testing::TestWithParam<std::string> {};

std::vector<std::string> all_exact_branch_specs() {
  std::vector<std::string> specs;
  for (const auto& entry : problem_registry()) {
    if (!entry.builtin) continue;
    for (const auto& spec : branch_specs(entry)) {
      if (make_problem(spec)->has(kExact)) specs.push_back(spec);
    }
  }
  return specs;
}

TEST_P(ExactBranch, MatchesTwoLibraryIntegrators) {
  const auto problem = make_problem(GetParam());
  ASSERT_TRUE(problem->has(kExact));
  const int n = problem->dof();
  const State start = problem->initial_state();
  // Past one period when there is one (phase, period and argument reduction all exercised),
  // sampled at twelfths of it: a declared period that is a multiple of the true one returns
  // early. Otherwise the default run, at most 20 time units.
  const bool periodic = problem->has(kPeriod);
  const double period = periodic ? problem->period() : 0;
  std::vector<double> times;
  if (periodic) {
    for (int k = 1; k <= 12; ++k) times.push_back(k * period / 12);
    times.push_back(1.37 * period);
  } else {
    // A stiff problem (stiff_spring at ratio 1e8) is followed for 2·10⁴ periods of its fastest
    // mode: explicit integrators at rtol 1e-13 need about 10⁸ stages for its default run.
    double t_end = std::min(problem->default_t_end(), 20.0);
    if (problem->has(kOmegaMax)) t_end = std::min(t_end, 2e4 / problem->omega_max(start.q));
    for (int k = 1; k <= 8; ++k) times.push_back(k * t_end / 8);
  }
  const Rhs rhs = [&](double t, const Vec& y) {
    return hamilton_rhs(*problem, t, y.head(n), y.tail(n));
  };
  // Absolute tolerance at 1e-13 of the state's size, so that neither integrator crawls on a
  // component that passes through zero; the size of the exact state at the end counts too, for a
  // motion that starts from rest at q = 0 (elastic_rod under its end load).
  const double size =
      std::max({inf_norm(stacked(start)), inf_norm(stacked(problem->exact(times.back()))), 1e-300});
  constexpr double kRtol = 1e-13;
  const std::vector<Trajectory> runs = {
      integrate_gsl_rk8pd(rhs, stacked(start), times, kRtol, kRtol * size),
      integrate_odeint_bulirsch_stoer(rhs, stacked(start), times, kRtol, kRtol * size)};
  const char* names[] = {"gsl_rk8pd", "odeint bulirsch_stoer"};
  double worst = 0;
  for (size_t k = 0; k < times.size(); ++k) {
    const Vec exact = stacked(problem->exact(times[k]));
    // Relative to the state's size over the run; 1e-9 leaves the integrators' global error (4e-10
    // at most, measured over these branches, at the pendulum's θ0 = 3.1) and catches any wrong
    // phase, period or branch formula.
    const double scale = std::max(inf_norm(exact), inf_norm(stacked(start)));
    // Near-collision orbits (Kepler at e ≥ 0.99) magnify the integrators' own error at each
    // perihelion; ten times their disagreement bounds it there.
    const double allowed = 1e-9 + 10 * inf_norm(runs[0][k] - runs[1][k]) / scale;
    for (size_t r = 0; r < runs.size(); ++r) {
      const double error = inf_norm(runs[r][k] - exact) / scale;
      worst = std::max(worst, error);
      EXPECT_LE(error, allowed) << names[r] << " at t = " << times[k] << "\n exact      "
                                << exact.transpose() << "\n integrated " << runs[r][k].transpose();
    }
    if (!periodic) continue;
    // A period is a return time of the integrated motion (angles modulo whole turns), and no
    // earlier twelfth of it is.
    for (size_t r = 0; r < runs.size(); ++r) {
      Vec change = runs[r][k] - stacked(start);
      if (problem->name() == "pendulum") {
        change[0] -= 2 * std::numbers::pi * std::round(change[0] / (2 * std::numbers::pi));
      }
      // φ = q[1] in polar Kepler and the spherical pendulum in angles.
      if (problem->spec().find("coordinates=polar") != std::string::npos ||
          problem->spec().find("coordinates=angles") != std::string::npos) {
        change[1] -= 2 * std::numbers::pi * std::round(change[1] / (2 * std::numbers::pi));
      }
      const double distance = inf_norm(change) / scale;
      if (k == 11) {
        EXPECT_LE(distance, allowed)
            << names[r] << ": no return after the declared period " << period;
      } else if (k < 11) {
        EXPECT_GT(distance, 1e-6) << names[r] << ": returns after " << k + 1
                                  << "/12 of the declared period " << period;
      }
    }
  }
  std::printf("%s: largest difference to the integrators %.2e\n", GetParam().c_str(), worst);
}

INSTANTIATE_TEST_SUITE_P(AllBranches, ExactBranch, ::testing::ValuesIn(all_exact_branch_specs()),
                         test_name);

// The variants of problems/registry.def are parameter sets of their own entry ("e=0.9", not
// "kepler:e=0.9" or an empty set), so each names a distinct, non-default test case.
TEST(ProblemRegistry, VariantsAreParameterSetsOfTheirEntry) {
  for (const auto& entry : problem_registry()) {
    for (const auto& variant : entry.variants) {
      const Spec spec = Spec::parse(entry.name + ":" + variant);
      EXPECT_EQ(spec.name, entry.name) << variant;
      EXPECT_FALSE(spec.values.empty()) << entry.name << ": empty variant";
    }
  }
}

TEST(ProblemFactory, UnknownProblemListsValidNames) {
  std::vector<std::string> named = {"no_such_problem"};
  for (const auto& entry : problem_registry()) named.push_back(entry.name);
  EXPECT_TRUE(test::input_error_names(make_problem, "no_such_problem:e=0.5", named));
}

TEST(ProblemFactory, CanonicalSpecSortsKeysAndFillsDefaults) {
  EXPECT_EQ(make_problem("kepler")->spec(), "kepler:e=0.6");
  EXPECT_EQ(make_problem("kepler:e=0.90")->spec(), "kepler:e=0.9");
  EXPECT_EQ(make_problem("harmonic:v0=2,omega=3")->spec(), "harmonic:mass=1,omega=3,q0=1,v0=2");
  EXPECT_EQ(make_problem("pendulum")->spec(), "pendulum:omega0=1,theta0=0.5,v0=0");
}

TEST(ProblemFactory, OutOfRangeValuesNameTheKey) {
  const test::InputErrorCases cases = {
      {"kepler:e=1.0", "e=1"},           {"kepler:e=-0.1", "e=-0.1"},
      {"harmonic:omega=-1", "omega=-1"}, {"harmonic:mass=0", "mass=0"},
      {"pendulum:omega0=0", "omega0=0"}, {"pendulum:theta0=inf", "theta0"},
  };
  EXPECT_TRUE(test::input_errors_name(make_problem, cases));
}

TEST(PendulumProblem, NearSeparatrixStillExact) {
  const auto problem = make_problem("pendulum:theta0=3.0");
  ASSERT_TRUE(problem->has(kExact));
  ASSERT_TRUE(problem->has(kPeriod));
  // Released from rest it swings to −θ0 in half a period (time symmetry); 1e-12 absolute
  // allows for the condition of the elliptic functions at k = sin(1.5).
  const State half = problem->exact(problem->period() / 2);
  EXPECT_NEAR(half.q[0], -3.0, 1e-12);
  EXPECT_NEAR(half.p[0], 0.0, 1e-12);
  // Near the separatrix the period is much longer than the small-angle 2π.
  EXPECT_GT(problem->period(), 2 * 2 * std::numbers::pi);
}

TEST(PendulumProblem, SeparatrixNeighbourhoodIsExact) {
  // θ0 = π − 1e-6: k' = cos(θ0/2) ≈ 5e-7, K = ln(4/k') + O(k'² ln k') (DLMF 19.12.1).
  const double theta0 = std::numbers::pi - 1e-6;
  const auto problem = make_problem("pendulum:theta0=" + format_number(theta0));
  ASSERT_TRUE(problem->has(kExact));
  ASSERT_TRUE(problem->has(kPeriod));
  const double complementary_modulus = std::cos(theta0 / 2);
  EXPECT_NEAR(problem->period(), 4 * std::log(4 / complementary_modulus), 1e-9);
  // Time symmetry: at half a period it is at −θ0 at rest, at a quarter at the bottom with
  // θ̇ = 2k (energy 2k²).
  const State half = problem->exact(problem->period() / 2);
  EXPECT_NEAR(half.q[0], -theta0, 1e-9);
  EXPECT_NEAR(half.p[0], 0.0, 1e-9);
  const State quarter = problem->exact(problem->period() / 4);
  EXPECT_NEAR(quarter.q[0], 0.0, 1e-9);
  EXPECT_NEAR(quarter.p[0], -2 * std::sin(theta0 / 2), 1e-9);
  // The equation of motion by central differences (the generic RK4 cross-check cannot follow
  // this orbit: a 1e-13 energy error already moves the period visibly).
  for (double t : {1.0, 20.0, 31.0, 50.0}) {
    constexpr double kH = 1e-4;
    const double rate_q = (problem->exact(t + kH).q[0] - problem->exact(t - kH).q[0]) / (2 * kH);
    const double rate_p = (problem->exact(t + kH).p[0] - problem->exact(t - kH).p[0]) / (2 * kH);
    const State at = problem->exact(t);
    EXPECT_NEAR(rate_q, at.p[0], 1e-6) << t;
    EXPECT_NEAR(rate_p, -std::sin(at.q[0]), 1e-6) << t;
    EXPECT_NEAR(problem->energy(at.q, at.p), 2 * std::pow(std::sin(theta0 / 2), 2), 1e-13) << t;
  }
  // On the separatrix itself there is no finite period, so nothing exact is declared.
  EXPECT_FALSE(make_problem("pendulum:theta0=0,v0=2")->has(kExact));
}

TEST(PendulumProblem, RotatingIsExactAndPeriodicModuloTwoPi) {
  const auto problem = make_problem("pendulum:theta0=0.3,v0=-3,omega0=1.5");
  ASSERT_TRUE(problem->has(kExact));
  ASSERT_TRUE(problem->has(kPeriod));
  const State start = problem->initial_state();
  const double period = problem->period();
  // One period is one revolution, here in the negative direction.
  for (int turns : {1, 2, 7}) {
    const State later = problem->exact(turns * period);
    EXPECT_NEAR(later.q[0], start.q[0] - 2 * std::numbers::pi * turns, 1e-10) << turns;
    EXPECT_NEAR(later.p[0], start.p[0], 1e-10) << turns;
  }
  // Time per revolution from the energy integral, T = ∫₀^{2π} dθ / |θ̇(θ)| (midpoint rule on a
  // smooth periodic integrand converges geometrically).
  const double energy = problem->energy(start.q, start.p);
  double integral = 0;
  constexpr int kNodes = 2000;
  for (int i = 0; i < kNodes; ++i) {
    const double theta = (i + 0.5) * 2 * std::numbers::pi / kNodes;
    const double s = std::sin(theta / 2);
    integral += 1 / std::sqrt(2 * (energy - 2 * 1.5 * 1.5 * s * s));
  }
  integral *= 2 * std::numbers::pi / kNodes;
  EXPECT_NEAR(period, integral, 1e-12 * integral);
  // Far above the separatrix the pendulum turns almost uniformly: T → 2π/|v0|.
  const auto fast = make_problem("pendulum:v0=1000");
  EXPECT_NEAR(fast->period(), 2 * std::numbers::pi / 1000, 1e-8);
}

TEST(PendulumProblem, PeriodMatchesSmallAmplitudeSeries) {
  // T = (2π/ω0)(1 + θ0²/16 + 11θ0⁴/3072 + O(θ0⁶)); at θ0 = 0.1 the O(θ0⁶) remainder is ~1e-7.
  const double theta0 = 0.1;
  const double omega0 = 2.5;
  const auto problem = make_problem("pendulum:theta0=0.1,omega0=2.5");
  const double series =
      2 * std::numbers::pi / omega0 * (1 + theta0 * theta0 / 16 + 11 * std::pow(theta0, 4) / 3072);
  EXPECT_NEAR(problem->period(), series, 1e-8 * series);
}

TEST(KeplerProblem, InvariantsMatchOrbitalElements) {
  // Semi-major axis 1: H = −1/(2a) = −½ and |L| = √(a(1 − e²)), to rounding.
  for (double e : {0.0, 0.3, 0.6, 0.9, 0.99}) {
    const auto problem = make_problem("kepler:e=" + format_number(e));
    const State start = problem->initial_state();
    EXPECT_NEAR(problem->energy(start.q, start.p), -0.5, 64 * DBL_EPSILON / (1 - e)) << e;
    EXPECT_NEAR(problem->angular_momentum(start.q, start.p)[0], std::sqrt(1 - e * e),
                16 * DBL_EPSILON)
        << e;
    // Aphelion at half a period: q = (−(1 + e), 0).
    const State aphelion = problem->exact(std::numbers::pi);
    EXPECT_NEAR(aphelion.q[0], -(1 + e), 16 * DBL_EPSILON) << e;
    EXPECT_NEAR(aphelion.q[1], 0.0, 16 * DBL_EPSILON) << e;
  }
}

// Kepler's equation at a mean anomaly where Newton alternates between two floats 4ε apart
// (E ≈ 2.87, ulp 2ε): the solver stops on its collapsed bracket instead of throwing, and the
// state still solves the equation: the energy is −½ to rounding.
TEST(KeplerProblem, ExactSolutionConvergesWhereNewtonAlternatesBetweenTwoFloats) {
  const auto problem = make_problem("kepler:e=0.3");
  const double t = 2.7888146928201127;
  State state;
  ASSERT_NO_THROW(state = problem->exact(t));
  EXPECT_NEAR(problem->energy(state.q, state.p), -0.5, 64 * DBL_EPSILON);
}

}  // namespace
}  // namespace problems_test
}  // namespace geomint
