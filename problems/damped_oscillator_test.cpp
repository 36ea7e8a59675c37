// Checks of the damped oscillator beyond the registry suite: the exact energy-decay law
// dH/dt = −2ζω v², the exact solution against the equation of motion for every damping regime
// (under-, critically, over-damped, driven, resonant), and parameter validation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <string>
#include <vector>

#include "problems/force.hpp"
#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace damped_oscillator_test {
namespace {

struct Case {
  std::string spec;
  double omega;
  double zeta;
  double drive = 0;
  double drive_omega = 0;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> list = {
      {"damped_oscillator", 1.0, 0.05},
      {"damped_oscillator:omega=2.5,zeta=0.3,q0=-0.4,v0=1.2", 2.5, 0.3},
      {"damped_oscillator:omega=0.7,zeta=0.9,q0=0,v0=-2", 0.7, 0.9},
      {"damped_oscillator:omega=3,zeta=1,q0=0.2,v0=4", 3, 1},
      {"damped_oscillator:omega=0.4,zeta=1.0000001,q0=-1,v0=0.3", 0.4, 1.0000001},
      {"damped_oscillator:omega=2,zeta=6,q0=1.5,v0=-20", 2, 6},
  };
  return list;
}

// Driven cases, including undamped resonance (the secular t·sin ωt term) and SI-sized values.
const std::vector<Case>& driven_cases() {
  static const std::vector<Case> list = {
      {"damped_oscillator:omega=2,zeta=0.1,q0=0.3,v0=-1,drive=0.8,drive_omega=1.3", 2, 0.1, 0.8,
       1.3},
      {"damped_oscillator:omega=1.5,zeta=0,q0=0,v0=0,drive=2,drive_omega=1.5", 1.5, 0, 2, 1.5},
      {"damped_oscillator:omega=1.5,zeta=0,q0=1,v0=0,drive=2,drive_omega=0.5", 1.5, 0, 2, 0.5},
      {"damped_oscillator:omega=50,zeta=2.5,q0=1e-3,v0=0,drive=400,drive_omega=80", 50, 2.5, 400,
       80},
      {"damped_oscillator:omega=0.5,zeta=1,q0=2,v0=1,drive=-0.1,drive_omega=3", 0.5, 1, -0.1, 3},
  };
  return list;
}

TEST(DampedOscillator, ExactEnergyDecaysAtPhysicalRate) {
  for (const Case& c : cases()) {
    const auto problem = make_problem(c.spec);
    const auto energy = [&](double t) {
      const State s = problem->exact(t);
      return problem->energy(s.q, s.p);
    };
    // Central differences with h = 1e-4/r, r = max(ω, 2ζω) the fastest rate (the fast root of an
    // overdamped oscillator): truncation ~ (hr)²H ~ 1e-8 H and rounding ~ ε H/h ~ 1e-12 rH,
    // both far inside 1e-6 rH(t).
    const double rate_scale = c.omega * std::max(1.0, 2 * c.zeta);
    const double h = 1e-4 / rate_scale;
    for (double t : {0.0, 0.3, 1.7, 4.2, 11.0, 23.5}) {
      const double rate = (energy(t + h) - energy(t - h)) / (2 * h);
      const double v = problem->exact(t).p[0];  // unit mass
      const double law = -2 * c.zeta * c.omega * v * v;
      EXPECT_NEAR(rate, law, 1e-6 * rate_scale * energy(t)) << c.spec << " t = " << t;
    }
  }
}

TEST(DampedOscillator, ExactSolvesEquationOfMotion) {
  std::vector<Case> all = cases();
  all.insert(all.end(), driven_cases().begin(), driven_cases().end());
  for (const Case& c : all) {
    const auto problem = make_problem(c.spec);
    const double rate_scale = std::max({c.omega, 2 * c.zeta * c.omega, c.drive_omega});
    const double h = 1e-4 / rate_scale;
    for (double t : {0.1, 2.3, 7.9, 19.0}) {
      const State at = problem->exact(t);
      const State before = problem->exact(t - h);
      const State after = problem->exact(t + h);
      const double q_rate = (after.q[0] - before.q[0]) / (2 * h);
      const double p_rate = (after.p[0] - before.p[0]) / (2 * h);
      // Amplitude of the solution (and of the drive, in units of q̈) at t sets the scale.
      const double scale = std::hypot(c.omega * at.q[0], at.p[0]) + std::abs(c.drive) / c.omega;
      EXPECT_NEAR(q_rate, at.p[0], 1e-7 * scale) << c.spec << " t = " << t;
      const double acceleration = -2 * c.zeta * c.omega * at.p[0] - c.omega * c.omega * at.q[0] +
                                  c.drive * std::cos(c.drive_omega * t);
      EXPECT_NEAR(p_rate, acceleration, 1e-7 * rate_scale * scale) << c.spec << " t = " << t;
      // The problem's own force is the same driving (the integrators see only force()).
      Vec f;
      force_of(*problem).force(at.q, at.p, t, f);
      EXPECT_NEAR(f[0] - c.omega * c.omega * at.q[0], acceleration, 1e-12 * c.omega * scale)
          << c.spec;
    }
  }
}

TEST(DampedOscillator, ForceAndDampingMatrixAgree) {
  const auto problem = make_problem("damped_oscillator:omega=2,zeta=0.25");
  ASSERT_TRUE(problem->has(kForce));
  ASSERT_TRUE(problem->has(kForceJacobian));
  const Vec q = Vec::Constant(1, 0.3);
  Vec f;
  force_of(*problem).force(q, Vec::Constant(1, -1.5), 0.0, f);
  EXPECT_NEAR(f[0], 2 * 0.25 * 2 * 1.5, 4 * DBL_EPSILON);
  SparseMatrix C;
  force_of(*problem).force_jacobian_v(q, Vec::Constant(1, -1.5), 0.0, C);
  EXPECT_NEAR(C.coeff(0, 0), 2 * 0.25 * 2, 4 * DBL_EPSILON);
}

TEST(DampedOscillator, UndampedIsConservativeHarmonic) {
  const auto damped = make_problem("damped_oscillator:omega=3,zeta=0,q0=0.5,v0=-1");
  const auto harmonic = make_problem("harmonic:omega=3,q0=0.5,v0=-1");
  EXPECT_FALSE(damped->has(kForce));
  for (double t : {0.4, 5.0, 33.0}) {
    const State a = damped->exact(t);
    const State b = harmonic->exact(t);
    EXPECT_NEAR(a.q[0], b.q[0], 1e-14) << t;
    EXPECT_NEAR(a.p[0], b.p[0], 4e-14) << t;
  }
}

TEST(DampedOscillator, ExactStartsAtTheInitialStateInEveryRegime) {
  std::vector<Case> all = cases();
  all.insert(all.end(), driven_cases().begin(), driven_cases().end());
  for (const Case& c : all) {
    const auto problem = make_problem(c.spec);
    const State start = problem->initial_state();
    const State exact = problem->exact(0.0);
    const double scale = std::abs(start.q[0]) + std::abs(start.p[0]) + 1e-300;
    EXPECT_NEAR(exact.q[0], start.q[0], 1e-14 * scale) << c.spec;
    EXPECT_NEAR(exact.p[0], start.p[0], 1e-14 * scale) << c.spec;
  }
}

// Critical damping is the limit of both sides: the exact solutions at ζ = 1 ± 1e-9 agree with
// ζ = 1 to O(1e-9), which catches a wrong sign or factor in either branch's formula.
TEST(DampedOscillator, CriticalDampingIsTheLimitOfBothSides) {
  const auto critical = make_problem("damped_oscillator:omega=1.7,zeta=1,q0=0.6,v0=-2");
  for (const char* zeta : {"0.999999999", "1.000000001"}) {
    const auto near =
        make_problem(std::string("damped_oscillator:omega=1.7,q0=0.6,v0=-2,zeta=") + zeta);
    for (double t : {0.2, 1.0, 3.0, 12.0}) {
      const State a = critical->exact(t);
      const State b = near->exact(t);
      const double scale = std::abs(a.q[0]) + std::abs(a.p[0]);
      EXPECT_NEAR(a.q[0], b.q[0], 1e-7 * scale) << zeta << " t = " << t;
      EXPECT_NEAR(a.p[0], b.p[0], 1e-7 * scale) << zeta << " t = " << t;
    }
  }
}

// Long after the transient a damped driven oscillator moves on its steady state with amplitude
// A/√((ω² − Ω²)² + (2ζωΩ)²).
TEST(DampedOscillator, DrivenSettlesOnTheResonanceCurve) {
  const double omega = 2, zeta = 0.1, drive = 0.8, drive_omega = 1.3;
  const auto problem =
      make_problem("damped_oscillator:omega=2,zeta=0.1,q0=0.3,v0=-1,drive=0.8,drive_omega=1.3");
  const double amplitude =
      drive / std::hypot(omega * omega - drive_omega * drive_omega, 2 * zeta * omega * drive_omega);
  double peak = 0;
  for (double t = 200; t < 200 + 2 * M_PI / drive_omega; t += 1e-3) {
    peak = std::max(peak, std::abs(problem->exact(t).q[0]));
  }
  EXPECT_NEAR(peak, amplitude, 1e-5 * amplitude);
}

TEST(DampedOscillator, UndrivenSpecIsUnchanged) {
  EXPECT_EQ(make_problem("damped_oscillator:zeta=0.1")->spec(),
            "damped_oscillator:omega=1,q0=1,v0=0,zeta=0.1");
  EXPECT_EQ(make_problem("damped_oscillator:drive=1")->spec(),
            "damped_oscillator:drive=1,drive_omega=1,omega=1,q0=1,v0=0,zeta=0.05");
}

TEST(DampedOscillator, RejectsNegativeDampingAndBadFrequency) {
  for (const auto& [spec, key] : std::vector<std::pair<std::string, std::string>>{
           {"damped_oscillator:drive_omega=-1", "drive_omega=-1"},
           {"damped_oscillator:zeta=-0.1", "zeta=-0.1"},
           {"damped_oscillator:omega=0", "omega=0"},
       }) {
    EXPECT_TRUE(test::input_error_names(make_problem, spec, key));
  }
}

// Linear drag F = −c v with c = 350 on a particle of mass 0.02 in a well of stiffness 8e3
// (non-unit scales), built without the registry: kForce and kForceJacobian come from the
// interface alone. `offer` makes as_forced() return it, `jacobian` is has_force_jacobian(),
// `claim` goes to set_capabilities (a problem that tries to declare the bits itself).
class Drag final : public Problem, public NonConservativeForce {
 public:
  Drag(bool offer, bool jacobian, unsigned claim) : offer_(offer), jacobian_(jacobian) {
    set_mass(Vec::Constant(1, 0.02));
    set_capabilities(kHessian | claim);
  }
  const NonConservativeForce* as_forced() const override { return offer_ ? this : nullptr; }
  bool has_force_jacobian() const override { return jacobian_; }
  State initial_state() const override {
    return {0.0, Vec::Constant(1, 1e-3), Vec::Constant(1, 0.02 * 4.0)};
  }
  double potential(const Vec& q) const override { return 0.5 * 8e3 * q.squaredNorm(); }
  void gradient(const Vec& q, Vec& g) const override { g = 8e3 * q; }
  void hessian(const Vec&, SparseMatrix& H) const override {
    H.resize(1, 1);
    H.insert(0, 0) = 8e3;
    H.makeCompressed();
  }
  void force(const Vec&, const Vec& v, double, Vec& f) const override { f = -350.0 * v; }
  void force_jacobian_v(const Vec& q, const Vec& v, double t, SparseMatrix& C) const override {
    if (!jacobian_) return NonConservativeForce::force_jacobian_v(q, v, t, C);  // throws
    C.resize(1, 1);
    C.insert(0, 0) = 350.0;
    C.makeCompressed();
  }

 private:
  bool offer_, jacobian_;
};

// One source of truth for kForce and kForceJacobian: as_forced() and has_force_jacobian() set
// them, the first-order view and the multipliers go through the query, and a problem that
// declares either bit is refused at construction.
TEST(NonConservativeForce, CapabilitiesFollowTheQueryAndCannotBeClaimed) {
  const Drag drag(true, true, 0);
  EXPECT_TRUE(drag.has(kForce));
  EXPECT_TRUE(drag.has(kForceJacobian));
  EXPECT_EQ(capability_names(drag.capabilities()),
            (std::vector<std::string>{"hessian", "force", "force_jacobian"}));
  EXPECT_EQ(&force_of(drag), static_cast<const NonConservativeForce*>(&drag));
  // ṗ = −k q − c v at q = 1e-3, v = 4: −8 − 1400.
  const State start = drag.initial_state();
  Vec y(2), ydot;
  drag.pack_first_order(start, y.data());
  drag.first_order_rhs(0.0, y, ydot);
  EXPECT_DOUBLE_EQ(ydot[0], 4.0);
  EXPECT_DOUBLE_EQ(ydot[1], -8.0 - 1400.0);
  // ∂ṗ/∂p = −c/m from the damping matrix.
  SparseMatrix J;
  drag.first_order_jacobian(0.0, y, J);
  EXPECT_DOUBLE_EQ(J.coeff(1, 1), -350.0 / 0.02);
  const Drag without_jacobian(true, false, 0);
  EXPECT_TRUE(without_jacobian.has(kForce));
  EXPECT_FALSE(without_jacobian.has(kForceJacobian));
  EXPECT_EQ(capability_names(without_jacobian.capabilities()),
            (std::vector<std::string>{"hessian", "force"}));
  SparseMatrix C;
  EXPECT_THROW(force_of(without_jacobian).force_jacobian_v(start.q, ydot, 0.0, C),
               std::logic_error);
  // Declining: no force anywhere, H is conserved (ṗ = −k q alone).
  const Drag declined(false, true, 0);
  EXPECT_FALSE(declined.has(kForce));
  EXPECT_FALSE(declined.has(kForceJacobian));
  EXPECT_THROW(force_of(declined), std::logic_error);
  declined.first_order_rhs(0.0, y, ydot);
  EXPECT_DOUBLE_EQ(ydot[1], -8.0);
  for (const unsigned claim : {unsigned{kForce}, unsigned{kForceJacobian}}) {
    try {
      Drag claimed(true, true, claim);
      ADD_FAILURE() << "set_capabilities accepted " << capability_names(claim)[0];
    } catch (const std::logic_error& error) {
      EXPECT_NE(std::string(error.what()).find(capability_names(claim)[0]), std::string::npos)
          << error.what();
    }
  }
}

}  // namespace
}  // namespace damped_oscillator_test
}  // namespace geomint
