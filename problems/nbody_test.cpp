// nbody (problems/nbody.cpp): the outer_solar_system alias is the same problem bit for bit, the
// parameter, CSV and preset routes agree, the centre-of-mass frame, and bad input; then the
// catalogue additions that start problems elsewhere (initial=FILE, chain init=node)
// and the time-dependent parametric oscillator.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "problems/problem.hpp"
#include "tests/test_util.hpp"

namespace geomint {
namespace nbody_test {
namespace {

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / name;
  std::ofstream(path) << text;
  return path.string();
}

TEST(NBody, OuterSolarSystemAliasIsTheSameProblemBitForBit) {
  const auto alias = make_problem("outer_solar_system:planets=4");
  const auto preset = make_problem("nbody:preset=outer_solar_system,planets=4");
  EXPECT_EQ(alias->spec(), "outer_solar_system:planets=4");
  ASSERT_EQ(alias->dof(), 15);
  const State start = alias->initial_state();
  EXPECT_EQ(start.q, preset->initial_state().q);
  EXPECT_EQ(start.p, preset->initial_state().p);
  EXPECT_EQ(alias->mass(), preset->mass());
  Vec g_alias, g_preset;
  alias->gradient(start.q, g_alias);
  preset->gradient(start.q, g_preset);
  EXPECT_EQ(g_alias, g_preset);
  EXPECT_EQ(alias->potential(start.q), preset->potential(start.q));
  // Jupiter's entry of GNI Table 2.1.
  EXPECT_EQ(start.q[3], -3.5023653);
  EXPECT_EQ(start.p[5], 0.000954786104043 * -0.00190589);
}

TEST(NBody, PleiadesIsTheTestSetProblem) {
  const auto problem = make_problem("nbody");
  EXPECT_EQ(problem->spec(), "nbody:frame=given,preset=pleiades");
  ASSERT_EQ(problem->dof(), 14);
  const State start = problem->initial_state();
  // Star 6 (mass 6) at (−2, −4) moving with ẋ = 1.75; star 4 (mass 4) with ẏ = −1.25.
  EXPECT_EQ(start.q[10], -2.0);
  EXPECT_EQ(start.q[11], -4.0);
  EXPECT_EQ(start.p[10], 6 * 1.75);
  EXPECT_EQ(start.p[7], 4 * -1.25);
  EXPECT_EQ(problem->mass()[13], 7.0);
  EXPECT_EQ(problem->angular_momentum(start.q, start.p).size(), 1);
  EXPECT_EQ(problem->default_t_end(), 3.0);
}

TEST(NBody, ParametersAndCsvFileGiveTheSameProblem) {
  const std::string path =
      write_temp("geomint_nbody_bodies.csv",
                 "m,x,y,z,vx,vy,vz\n2,1,0,0,0,0.4,0.1\n"
                 "0.5,-1,0.5,0,0.2,-0.6,0\n# third\n1.5,0,-1,0.3,-0.3,0.1,0.2\n");
  const auto from_file = make_problem("nbody:preset=custom,G=1.3,file=" + path);
  const auto from_lists = make_problem(
      "nbody:preset=custom,dim=3,masses=2/0.5/1.5,positions=1/0/0/-1/0.5/0/0/-1/0.3,"
      "velocities=0/0.4/0.1/0.2/-0.6/0/-0.3/0.1/0.2,G=1.3");
  EXPECT_EQ(from_file->initial_state().q, from_lists->initial_state().q);
  EXPECT_EQ(from_file->initial_state().p, from_lists->initial_state().p);
  EXPECT_EQ(from_file->potential(from_file->initial_state().q),
            from_lists->potential(from_lists->initial_state().q));
  EXPECT_EQ(
      from_lists->angular_momentum(from_lists->initial_state().q, from_lists->initial_state().p)
          .size(),
      3);
  std::filesystem::remove(path);
}

TEST(NBody, CentreOfMassFrameZeroesMassWeightedSums) {
  const auto problem = make_problem(
      "nbody:preset=custom,masses=3/0.25,positions=0/0/1.5/0,velocities=0/-0.1/0/1.3,"
      "frame=com");
  const State start = problem->initial_state();
  EXPECT_NEAR(3 * start.q[0] + 0.25 * start.q[2], 0.0, 1e-15);
  EXPECT_NEAR(3 * start.q[1] + 0.25 * start.q[3], 0.0, 1e-15);
  EXPECT_NEAR(problem->linear_momentum(start.q, start.p).norm(), 0.0, 1e-15);
  // The relative motion is untouched.
  EXPECT_DOUBLE_EQ(start.q[2] - start.q[0], 1.5);
  EXPECT_DOUBLE_EQ(start.p[3] / 0.25 - start.p[1] / 3, 1.4);
}

TEST(NBody, BadInputNamesTheProblem) {
  EXPECT_TRUE(test::input_errors_name(
      make_problem, {{"nbody:preset=custom,masses=1/2,positions=0/0/1", "positions"},
                     {"nbody:preset=custom,masses=1/x,positions=0/0/1/0", "masses"},
                     {"nbody:preset=custom,masses=1,positions=0/0", "at least 2 bodies"},
                     {"nbody:preset=custom,masses=1/-2,positions=0/0/1/0", "mass must be > 0"},
                     {"nbody:preset=custom,masses=1/2,positions=0/0/0/0", "same position"},
                     {"nbody:preset=custom,file=/no/such/file.csv", "file="},
                     {"nbody:preset=pleiades,planets=3", "planets"},
                     {"nbody:preset=custom,masses=1/2,positions=0/0/1/0,G=0", "G"}}));
  const std::string path = write_temp("geomint_nbody_bad.csv", "1,0,0,0,0\n2,1,0,0\n");
  EXPECT_TRUE(
      test::input_error_names(make_problem, "nbody:preset=custom,file=" + path, "4 columns"));
  std::filesystem::remove(path);
}

// initial=FILE replaces the start of any problem and drops what belonged to the old one.
TEST(InitialStateFile, ReplacesTheStartAndDropsTheExactSolution) {
  const std::string path = write_temp("geomint_initial_qv.csv", "q,v\n0.25,-1.5\n");
  const auto problem = make_problem("harmonic:mass=2,initial=" + path);
  EXPECT_EQ(problem->spec(), "harmonic:initial=" + path + ",mass=2,omega=1,q0=1,v0=0");
  EXPECT_EQ(problem->initial_state().q[0], 0.25);
  EXPECT_EQ(problem->initial_state().p[0], 2 * -1.5);  // q,v header: p = m v
  EXPECT_FALSE(problem->has(kExact));
  EXPECT_FALSE(problem->has(kPeriod));
  EXPECT_TRUE(problem->has(kHessian));
  EXPECT_EQ(make_problem(problem->spec())->spec(), problem->spec());
  std::filesystem::remove(path);
}

TEST(InitialStateFile, WrongLengthNamesTheDofAndConstraintsAreChecked) {
  const std::string three = write_temp("geomint_initial_three.csv", "q,p\n0,0\n1,0\n2,0\n");
  EXPECT_TRUE(test::input_error_names(make_problem, "kepler:initial=" + three,
                                      std::vector<std::string>{"n = 2", "3 rows"}));
  // A rod of length 2.5 with the bob at radius 2: an inconsistent start.
  const std::string off_rod = write_temp("geomint_initial_rod.csv", "2,0\n0,0\n");
  EXPECT_TRUE(test::input_error_names(
      make_problem, "cartesian_pendulum:length=2.5,initial=" + off_rod, "initial state"));
  const std::string on_rod = write_temp("geomint_initial_on_rod.csv", "0,1\n-2.5,0\n");
  const auto wrapped = make_problem("cartesian_pendulum:length=2.5,initial=" + on_rod);
  EXPECT_EQ(wrapped->initial_state().q[1], -2.5);
  // The wrapper passes the constraints through (as_constrained(), hence kConstraints) but not
  // the exact multipliers, which belong to the problem's own start like exact().
  ASSERT_NE(wrapped->as_constrained(), nullptr);
  EXPECT_TRUE(wrapped->has(kConstraints));
  EXPECT_FALSE(wrapped->has(kTimeDependentConstraints));
  EXPECT_EQ(wrapped->as_constrained()->multiplier_names(), std::vector<std::string>{"tension"});
  EXPECT_TRUE(
      make_problem("cartesian_pendulum:length=2.5")->as_constrained()->exact_multipliers(0.3));
  EXPECT_FALSE(wrapped->as_constrained()->exact_multipliers(0.3));
  // A rheonomic problem stays rheonomic: car_axis from its own start, written out in full.
  const State car_state = make_problem("car_axis")->initial_state();
  std::string car_rows;
  for (int i = 0; i < car_state.q.size(); ++i) {
    char row[64];
    std::snprintf(row, sizeof row, "%.17g,%.17g\n", car_state.q[i], car_state.p[i]);
    car_rows += row;
  }
  const std::string car_start = write_temp("geomint_initial_car.csv", car_rows);
  const auto car = make_problem("car_axis:initial=" + car_start);
  EXPECT_TRUE(car->has(kConstraints));
  EXPECT_TRUE(car->has(kTimeDependentConstraints));
  const std::string garbage = write_temp("geomint_initial_garbage.csv", "q,p\n1,x\n");
  EXPECT_TRUE(test::input_error_names(make_problem, "harmonic:initial=" + garbage, ":2:"));
  for (const auto& path : {three, off_rod, on_rod, garbage, car_start}) {
    std::filesystem::remove(path);
  }
}

TEST(SpringChainNodeInit, DisplacesOneNodeAndKeepsTheExactSolution) {
  const auto problem = make_problem("spring_chain:init=node,node=3,n=6,mass=0.7,amplitude=0.3");
  const State start = problem->initial_state();
  for (int i = 0; i < 6; ++i) EXPECT_EQ(start.q[i], i == 2 ? 0.3 : 0.0) << i;
  ASSERT_TRUE(problem->has(kExact));
  const State again = problem->exact(0.0);
  EXPECT_LE((again.q - start.q).lpNorm<Eigen::Infinity>(), 1e-15);
  // The mode init's canonical spec is unchanged (init=mode is the omitted default).
  EXPECT_EQ(make_problem("spring_chain:mode=2")->spec().find("init"), std::string::npos);
  EXPECT_TRUE(test::input_error_names(make_problem, "spring_chain:init=node,node=7,n=6", "node=7"));
  EXPECT_TRUE(test::input_error_names(make_problem, "spring_chain:init=node,mode=2", "mode"));
}

// y' of the first-order view, classical RK4 with n steps: an independent check that needs no
// integrator library.
State rk4(const Problem& problem, double t_end, int n) {
  const State start = problem.initial_state();
  const int d = problem.dof();
  Vec y(2 * d), k1, k2, k3, k4;
  y << start.q, start.p;
  const double h = t_end / n;
  for (int i = 0; i < n; ++i) {
    const double t = i * h;
    problem.first_order_rhs(t, y, k1);
    problem.first_order_rhs(t + h / 2, y + h / 2 * k1, k2);
    problem.first_order_rhs(t + h / 2, y + h / 2 * k2, k3);
    problem.first_order_rhs(t + h, y + h * k3, k4);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return {t_end, y.head(d), y.tail(d)};
}

// Mathieu's first instability tongue: at ν = 2ω the amplitude grows like exp(εωt/4), so the
// energy like exp(εωt/2); off resonance it stays bounded. Fails if the modulation ignores t.
TEST(ParametricOscillator, ResonatesAtTwiceTheFrequency) {
  const double epsilon = 0.1, t_end = 400;
  const auto resonant = make_problem("parametric_oscillator:omega=1,epsilon=0.1,nu=2");
  const auto detuned = make_problem("parametric_oscillator:omega=1,epsilon=0.1,nu=1.3");
  const State start = resonant->initial_state();
  const double e0 = resonant->energy(start.q, start.p);
  const State end_resonant = rk4(*resonant, t_end, 80000);
  const State end_detuned = rk4(*detuned, t_end, 80000);
  const double growth = std::log(resonant->energy(end_resonant.q, end_resonant.p) / e0) / t_end;
  std::printf("parametric resonance: energy growth rate %.4f (theory εω/2 = %.4f)\n", growth,
              epsilon / 2);
  EXPECT_NEAR(growth, epsilon / 2, 0.15 * epsilon / 2);
  EXPECT_LT(detuned->energy(end_detuned.q, end_detuned.p), 2 * e0);
}

}  // namespace
}  // namespace nbody_test
}  // namespace geomint
