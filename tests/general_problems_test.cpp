// The general-kind problems against their constrained Cartesian twins (../shared/MECHANICS.md §5,
// §7 "cross-formulation equality"): rod_chain in joint angles and spherical_pendulum in angles
// start in the same physical state, with the same energy, and move the same way; a run through
// the spherical pendulum's pole is a failure row, never a NaN reported as ok; the charged
// particle's magnetic moment metric; a general-kind row's method spec re-runs it; initial=FILE
// with the position-dependent mass.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "harness/run.hpp"
#include "harness/table.hpp"
#include "integrators/integrator.hpp"
#include "problems/lagrangian.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace general_problems_test {
namespace {

double inf_norm(const Vec& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

// Node positions x_i = Σ_{k ≤ i} l_k (sin θ_k, −cos θ_k) of the chain with rod lengths
// l_k = length · length_ratio^(k−1).
Vec chain_nodes(const Vec& theta, double length, double length_ratio) {
  Vec x(2 * theta.size());
  double px = 0, py = 0;
  for (int i = 0; i < theta.size(); ++i) {
    const double l = length * std::pow(length_ratio, i);
    px += l * std::sin(theta[i]);
    py -= l * std::cos(theta[i]);
    x.segment(2 * i, 2) << px, py;
  }
  return x;
}

constexpr const char* kChains[] = {
    "n=1,theta=0.8,mass=1.7,length=0.4,gravity=2.5,omega=-0.6",
    "n=2,mass=1.3,mass_ratio=0.6,length=0.9,length_ratio=1.7,gravity=2.5,theta1=0.3,"
    "theta2=-0.2,omega=0.4",
    "n=3,mass=2,mass_ratio=0.5,length=0.7,length_ratio=1.5,gravity=2.5,theta1=0.3,"
    "theta2=-1.1,theta3=2.5,omega=0.4",
    "n=5,theta=1,mass=0.3,gravity=9.81,omega=0.2"};

// The same parameters give the same start: node positions, and T + V through M(θ) and p = M θ̇
// against Σ|p_i|²/2m_i + V in Cartesian coordinates, to round-off.
TEST(RodChainJoint, StartsInTheCartesianChainsStateWithItsEnergy) {
  for (const char* parameters : kChains) {
    const auto joint = make_problem(std::string("rod_chain:coordinates=joint,") + parameters);
    const auto cartesian = make_problem(std::string("rod_chain:") + parameters);
    ASSERT_TRUE(joint->kind() == ProblemKind::kLagrangian);
    const State a = joint->initial_state();
    const State c = cartesian->initial_state();
    const auto spec = joint->spec();
    const auto value = [&](const std::string& key) {
      const auto at = spec.find("," + key + "=");
      return std::stod(spec.substr(at + key.size() + 2));
    };
    EXPECT_LE(inf_norm(chain_nodes(a.q, value("length"), value("length_ratio")) - c.q),
              1e-15 * inf_norm(c.q))
        << parameters;
    const double e_joint = joint->energy(a.q, a.p);
    const double e_cartesian = cartesian->energy(c.q, c.p);
    const double size = std::abs(cartesian->potential(c.q)) + std::abs(e_cartesian);
    EXPECT_LE(std::abs(e_joint - e_cartesian), 1e-14 * size)
        << parameters << ": joint " << e_joint << " Cartesian " << e_cartesian;
  }
}

// Short runs of the two formulations agree within their own error estimates (Richardson: the
// difference between steps h and h/2, times 2^r/(2^r − 1) for order r): RATTLE (order 2) on the
// constrained Cartesian chain, RK4 (order 4) on the joint angles, mapped to node positions.
TEST(RodChainJoint, ShortRunsAgreeWithTheCartesianChainWithinTheirErrorEstimates) {
  for (const char* parameters : {kChains[1], kChains[2]}) {
    const std::string joint = std::string("rod_chain:coordinates=joint,") + parameters;
    const std::string cartesian = std::string("rod_chain:") + parameters;
    const auto joint_problem = make_problem(joint);
    const auto spec = joint_problem->spec();
    const auto value = [&](const std::string& key) {
      const auto at = spec.find("," + key + "=");
      return std::stod(spec.substr(at + key.size() + 2));
    };
    const auto final_q = [](const std::string& problem, const std::string& method, double dt) {
      RunConfig config;
      config.dt = dt;
      config.t_end = 0.5;
      config.timing_repeats = 0;
      const RunResult result = run_one(problem, method, config);
      EXPECT_TRUE(result.ok) << problem << " " << method << ": " << result.record.status;
      return result.final_state.q;
    };
    const double h = 0.005;
    const Vec joint_h =
        chain_nodes(final_q(joint, "rk4", h), value("length"), value("length_ratio"));
    const Vec joint_half =
        chain_nodes(final_q(joint, "rk4", h / 2), value("length"), value("length_ratio"));
    const Vec cartesian_h = final_q(cartesian, "rattle", h);
    const Vec cartesian_half = final_q(cartesian, "rattle", h / 2);
    const double joint_error = inf_norm(joint_h - joint_half) * 16 / 15;
    const double cartesian_error = inf_norm(cartesian_h - cartesian_half) * 4 / 3;
    const double difference = inf_norm(joint_half - cartesian_half);
    // The estimates are of the leading term only: twice their sum.
    EXPECT_LE(difference, 2 * (joint_error + cartesian_error) + 1e-13)
        << parameters << ": joint error ~" << joint_error << ", Cartesian error ~"
        << cartesian_error;
    // Not vacuous: the Cartesian estimate is resolved, and the runs moved.
    EXPECT_GT(cartesian_error, 1e-9) << parameters;
    EXPECT_GT(inf_norm(cartesian_half - make_problem(cartesian)->initial_state().q), 1e-3);
  }
}

// The same pendulum in angles and in constrained Cartesian coordinates: equal energy and
// vertical angular momentum p_φ = x p_y − y p_x at the start, to round-off.
TEST(SphericalPendulumAngles, StartsWithTheCartesianEnergyAndVerticalMomentum) {
  for (const char* parameters : {"theta0=1", "length=2.5,gravity=3,mass=0.4,theta0=0.7,phi0=0.3",
                                 "theta0=2.2,theta_dot0=0.4,phi_dot0=-0.9,mass=3,length=0.6"}) {
    const auto angles =
        make_problem(std::string("spherical_pendulum:coordinates=angles,") + parameters);
    const auto cartesian = make_problem(std::string("spherical_pendulum:") + parameters);
    const State a = angles->initial_state();
    const State c = cartesian->initial_state();
    const double size = std::abs(cartesian->potential(c.q)) + std::abs(cartesian->energy(c.q, c.p));
    EXPECT_LE(std::abs(angles->energy(a.q, a.p) - cartesian->energy(c.q, c.p)), 1e-14 * size)
        << parameters;
    const double momentum = cartesian->angular_momentum(c.q, c.p)[0];
    EXPECT_NEAR(angles->angular_momentum(a.q, a.p)[0], momentum, 1e-14 * std::abs(momentum))
        << parameters;
  }
}

// A small p_φ sends the pendulum through the lower pole θ = 0, where M = mL² diag(1, sin²θ) is
// singular and φ̇ = p_φ/(mL² sin²θ) explodes: each method's row is a failure (Newton fails, the
// energy diverges, or the state or energy is not finite), never ok with NaN metrics. The same
// start with the conical φ̇₀ is an ok run. The crossing at t = 8.17 throws rk4's relative energy
// error to ~1e6, finite or not by the luck of the rounding there (a failure row with rk4's former
// general-kind step, 1.9e6 at t = 20 with its one step): below the default divergence factor
// 1e8, so the test asks for the `diverged` rule at 1e3, which the conical run stays far below.
TEST(SphericalPendulumAngles, RunThroughThePoleIsAFailureRow) {
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 20;
  config.timing_repeats = 0;
  config.diverge_factor = 1e3;
  for (const char* method : {"del", "rk4"}) {
    const RunResult through_pole =
        run_one("spherical_pendulum:coordinates=angles,theta0=0.5,phi_dot0=1e-3", method, config);
    EXPECT_FALSE(through_pole.ok) << method;
    EXPECT_NE(through_pole.record.status, "ok") << method;
    const RunResult conical =
        run_one("spherical_pendulum:coordinates=angles,theta0=0.5", method, config);
    EXPECT_TRUE(conical.ok) << method << ": " << conical.record.status;
    for (const auto& [name, metric] : conical.record.metrics) {
      EXPECT_FALSE(std::isnan(metric)) << method << " " << name;
    }
  }
}

// magnetic_moment_err_max (harness/observers.cpp) against the problem's own `magnetic_moment`
// series column (problems/charged_particle.cpp), written independently, along a Boris run in the
// bottle (a moment that varies: the comparison has something to compare) at non-unit m, q, B.
TEST(MagneticMoment, MetricIsTheSeriesColumnsLargestRelativeChange) {
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / "geomint_magnetic_moment";
  std::filesystem::create_directories(dir);
  RunConfig config;
  config.dt = 0.16178;
  config.t_end = 50;
  config.timing_repeats = 0;
  config.series_path = (dir / "series.csv").string();
  const RunResult result =
      run_one("charged_particle:field=bottle,mass=1.3,charge=0.8,B=2,length=1.5,vx=1,vz=0.5,z0=0.1",
              "boris", config);
  ASSERT_TRUE(result.ok) << result.record.status;
  const CsvTable table = read_csv_file(config.series_path);
  ASSERT_GE(table.rows.size(), 100u);
  const double mu0 = std::stod(table.rows.front().at("magnetic_moment"));
  double worst = 0;
  for (const Row& row : table.rows) {
    worst = std::max(worst, std::abs(std::stod(row.at("magnetic_moment")) - mu0) / mu0);
  }
  const double metric = result.record.metrics.at("magnetic_moment_err_max");
  EXPECT_GT(worst, 1e-2);  // the bottle of length 1.5 is far from adiabatic: μ swings by ~20%
  EXPECT_NEAR(metric, worst, 1e-12 * worst);
  std::filesystem::remove_all(dir);
}

// In a uniform B the Boris rotation keeps |v⊥| exactly: μ to round-off over 100 gyrations, even
// for an electron in SI units (μ ~ 1e-18 J/T, hence relative). Other problems have no column.
TEST(MagneticMoment, BorisKeepsItInAUniformFieldAndOnlyChargedParticlesHaveIt) {
  RunConfig config;
  config.timing_repeats = 0;
  config.dt = 0.396825396825397;
  config.t_end = 1246.66375;
  const RunResult helix =
      run_one("charged_particle:mass=2.5,charge=-0.7,B=1.8,vx=0.4,vy=-1.3,vz=0.5", "boris", config);
  ASSERT_TRUE(helix.ok);
  EXPECT_LE(helix.record.metrics.at("magnetic_moment_err_max"), 1e-13);
  config.dt = 0.2 / 1.759e11;
  config.t_end = 100 * 2 * 3.141592653589793 / 1.759e11;
  const RunResult electron = run_one(
      "charged_particle:mass=9.109e-31,charge=-1.602e-19,B=1,vx=1e6,vz=2e5", "boris", config);
  ASSERT_TRUE(electron.ok);
  EXPECT_LE(electron.record.metrics.at("magnetic_moment_err_max"), 1e-13);
  config.dt = 0.05;
  config.t_end = 1;
  EXPECT_EQ(run_one("kepler", "rk4", config).record.metrics.count("magnetic_moment_err_max"), 0u);
}

// Every row of a general-kind run names what ran: re-running the row's method spec reproduces
// the row (same canonical spec, status, metrics and final state, bit for bit). `hp` without
// solver= runs Newton there, and its row reads hp:…,solver=newton (the separable default
// solver=minimize would be refused on a re-run). Every applicable method of the registry on one
// spec of each non-separable problem and coordinate system, a few steps each.
TEST(GeneralRows, RerunningARowsMethodSpecReproducesIt) {
  std::set<std::string> kinds;
  int rows = 0, resolved = 0;
  for (const auto& problem_spec : problem_test_specs()) {
    const auto problem = make_problem(problem_spec);
    if (problem->kind() != ProblemKind::kLagrangian) continue;
    const Spec canonical = Spec::parse(problem->spec());
    const auto coordinates = canonical.values.find("coordinates");
    const std::string kind =
        canonical.name + (coordinates == canonical.values.end() ? "" : coordinates->second);
    if (!kinds.insert(kind).second) continue;
    RunConfig config;
    config.dt = problem->default_dt();
    config.t_end = 2 * config.dt;
    config.timing_repeats = 0;
    for (const auto& method_spec : integrator_test_specs()) {
      const auto method = make_integrator(method_spec);
      if (!applicable(*method, *problem).ok) continue;
      const RunResult row = run_one(problem_spec, method_spec, config);
      const std::string where = problem_spec + " " + method_spec + " -> " + row.record.method;
      RunResult again;
      try {
        again = run_one(problem_spec, row.record.method, config);
      } catch (const InputError& error) {
        ADD_FAILURE() << where << ": the row's spec is refused: " << error.what();
        continue;
      }
      EXPECT_EQ(again.record.method, row.record.method) << where;
      EXPECT_EQ(again.record.status, row.record.status) << where;
      EXPECT_EQ(again.record.steps, row.record.steps) << where;
      EXPECT_TRUE(again.final_state.q == row.final_state.q) << where;
      EXPECT_TRUE(again.final_state.p == row.final_state.p) << where;
      for (const auto& [name, value] : row.record.metrics) {
        const double other = again.record.metrics.at(name);
        EXPECT_TRUE(other == value || (std::isnan(other) && std::isnan(value)))
            << where << ": " << name << " " << value << " then " << other;
      }
      ++rows;
      if (row.record.method != method->spec()) ++resolved;
    }
  }
  EXPECT_GE(kinds.size(), 6u);
  EXPECT_GE(rows, 50);
  EXPECT_GE(resolved, 1);  // hp (solver=minimize by default) ran as hp:…,solver=newton
}

// initial=FILE on the general kind: a q,v file gives the canonical p = M(q)v (written out here
// for the double pendulum at non-unit masses and lengths), and the problem started from its own
// start through a file runs exactly as the problem itself — so the wrapper forwards M(q) (it
// has no constant mass).
TEST(GeneralRows, InitialStateFileUsesThePositionDependentMass) {
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / "geomint_general_initial";
  std::filesystem::create_directories(dir);
  const double m1 = 1.3, m2 = 0.7, l1 = 0.9, l2 = 1.6;
  const std::string base = "double_pendulum:m1=1.3,m2=0.7,l1=0.9,l2=1.6,g=2.5";
  const std::string velocities = (dir / "qv.csv").string();
  std::ofstream(velocities) << "q,v\n0.4,-0.3\n-0.7,1.1\n";
  const State start = make_problem(base + ",initial=" + velocities)->initial_state();
  const double c = std::cos(0.4 - -0.7);
  EXPECT_NEAR(start.p[0], (m1 + m2) * l1 * l1 * -0.3 + m2 * l1 * l2 * c * 1.1, 1e-15);
  EXPECT_NEAR(start.p[1], m2 * l1 * l2 * c * -0.3 + m2 * l2 * l2 * 1.1, 1e-15);

  const auto own = make_problem(base);
  const State own_start = own->initial_state();
  const std::string momenta = (dir / "qp.csv").string();
  std::ofstream(momenta) << fmt::format("q,p\n{:.17g},{:.17g}\n{:.17g},{:.17g}\n", own_start.q[0],
                                        own_start.p[0], own_start.q[1], own_start.p[1]);
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 0.5;
  config.timing_repeats = 0;
  for (const char* method : {"del", "rk4", "cvode_bdf"}) {
    const RunResult direct = run_one(base, method, config);
    const RunResult from_file = run_one(base + ",initial=" + momenta, method, config);
    ASSERT_TRUE(direct.ok && from_file.ok) << method << ": " << from_file.record.status;
    EXPECT_TRUE(from_file.final_state.q == direct.final_state.q) << method;
    EXPECT_TRUE(from_file.final_state.p == direct.final_state.p) << method;
    EXPECT_EQ(from_file.record.metrics.at("energy_err_max"),
              direct.record.metrics.at("energy_err_max"))
        << method;
  }
  std::filesystem::remove_all(dir);
}

// A charged particle started from a file keeps its mass, charge and fields
// (Problem::as<ChargedParticleStructure>() forwarded by the initial= wrapper): Boris runs, and it
// and the magnetic-moment metric give the direct run's bits from the same start.
TEST(GeneralRows, ChargedParticleFromAFileKeepsItsFields) {
  const std::filesystem::path dir =
      std::filesystem::path(testing::TempDir()) / "geomint_charged_initial";
  std::filesystem::create_directories(dir);
  const std::string base =
      "charged_particle:field=bottle,mass=1.3,charge=0.8,B=2,length=1.5,vx=1,vz=0.5,z0=0.1,xc=0.05";
  const State own_start = make_problem(base)->initial_state();
  const std::string momenta = (dir / "qp.csv").string();
  {
    std::ofstream file(momenta);
    file << "q,p\n";
    for (int i = 0; i < 3; ++i) {
      file << fmt::format("{:.17g},{:.17g}\n", own_start.q[i], own_start.p[i]);
    }
  }
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 0.3;
  config.timing_repeats = 0;
  for (const char* method : {"boris", "del"}) {
    const RunResult direct = run_one(base, method, config);
    const RunResult from_file = run_one(base + ",initial=" + momenta, method, config);
    ASSERT_TRUE(direct.ok && from_file.ok) << method << ": " << from_file.record.status;
    EXPECT_TRUE(from_file.final_state.q == direct.final_state.q) << method;
    EXPECT_TRUE(from_file.final_state.p == direct.final_state.p) << method;
    ASSERT_EQ(from_file.record.metrics.count("magnetic_moment_err_max"), 1u) << method;
    EXPECT_EQ(from_file.record.metrics.at("magnetic_moment_err_max"),
              direct.record.metrics.at("magnetic_moment_err_max"))
        << method;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace general_problems_test
}  // namespace geomint
