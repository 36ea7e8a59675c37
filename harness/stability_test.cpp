// Tests of the linear-stability search (harness/stability.hpp) against the known limits of
// docs/METHOD.md §7 on the harmonic oscillator.
#include "harness/stability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "harness/run_spec.hpp"
#include "harness/sweep.hpp"
#include "integrators/integrator.hpp"

namespace geomint {
namespace stability_test {
namespace {

// A search from the specs the test names.
StabilityResult search(const std::string& problem, const std::string& method,
                       const StabilityOptions& options) {
  return stability_search(*parse_problem(problem), MethodFactory(method), options);
}

StabilityOptions fast_options() {
  StabilityOptions options;
  options.homega_min = 0.05;
  options.homega_max = 200;
  options.periods = 100;
  options.min_steps = 5000;
  return options;
}

TEST(Stability, StormerVerletLimitIsTwo) {
  const auto result = search("harmonic:omega=3", "stormer_verlet", fast_options());
  EXPECT_EQ(result.status, "bracketed");
  EXPECT_NEAR(result.homega_limit, 2.0, 1e-3);
  EXPECT_EQ(result.predicted, 2.0);
}

TEST(Stability, SymplecticEulerReachesTwoDespiteItsDegenerateInvariant) {
  // Close to hω = 2 the conserved quadratic form makes H/H₀ = 1/(1 − hω/2) while bounded: the
  // growth factor must not mistake this for instability.
  const auto result = search("harmonic", "symplectic_euler_a", fast_options());
  EXPECT_NEAR(result.homega_limit, 2.0, 1e-3);
}

TEST(Stability, ExplicitEulerIsUnstableForEveryStep) {
  const auto result = search("harmonic", "explicit_euler", fast_options());
  EXPECT_EQ(result.status, "unstable_at_min");
  EXPECT_EQ(result.homega_limit, 0.0);
  EXPECT_EQ(result.predicted, 0.0);
}

TEST(Stability, ImplicitMidpointIsStableUpToTheTopOfTheRange) {
  for (const char* method : {"implicit_midpoint", "hp:alpha=0.5", "implicit_euler"}) {
    const auto result = search("harmonic", method, fast_options());
    EXPECT_EQ(result.status, "stable_to_max") << method;
    EXPECT_EQ(result.homega_limit, 200.0) << method;
    EXPECT_TRUE(std::isinf(result.predicted)) << method;
  }
}

TEST(Stability, AlphaRuleFollowsOneOverDistanceFromOneHalf) {
  for (const double alpha : {0.25, 0.75}) {
    const auto result = search("harmonic", "hp:alpha=" + format_number(alpha), fast_options());
    EXPECT_NEAR(result.homega_limit, 1 / std::abs(0.5 - alpha), 4e-3) << alpha;
  }
  EXPECT_NEAR(search("harmonic", "rk4", fast_options()).homega_limit, 2 * std::sqrt(2.0), 3e-3);
}

TEST(Stability, PredictionsFromTheCanonicalSpec) {
  EXPECT_EQ(predicted_homega_limit(MethodFactory("hp:alpha=0.1")), 2.5);
  EXPECT_EQ(predicted_homega_limit(MethodFactory("del:rule=trapezoid")), 2.0);
  EXPECT_TRUE(std::isinf(predicted_homega_limit(MethodFactory("del"))));
  EXPECT_NEAR(predicted_homega_limit(MethodFactory("del:rule=symmetric_alpha,alpha=0.25")), 4.0,
              1e-15);
  EXPECT_NEAR(predicted_homega_limit(MethodFactory("newmark:beta=0.1,gamma=0.5")),
              1 / std::sqrt(0.15), 1e-15);
  EXPECT_TRUE(std::isinf(predicted_homega_limit(MethodFactory("newmark:beta=0.25,gamma=0.5"))));
  EXPECT_TRUE(std::isnan(predicted_homega_limit(MethodFactory("odeint_mclachlan4"))));
}

// Every method of the registry, in every configuration the registry tests, predicts its linear
// stability limit or says why it cannot; where it predicts one for a fixed-step method, the
// search on the harmonic oscillator measures it.
TEST(Stability, EveryMethodPredictsItsLimitOrSaysWhyNot) {
  StabilityOptions options = fast_options();
  options.min_steps = 2000;
  options.rel_tol = 1e-5;
  int compared = 0;
  for (const std::string& spec : integrator_test_specs()) {
    const auto integrator = make_integrator(spec);
    const StabilityPrediction prediction = integrator->predicted_linear_stability();
    EXPECT_TRUE(prediction.predicted() != !prediction.reason.empty())
        << spec << ": a limit or a reason, not both, not neither (reason '" << prediction.reason
        << "')";
    if (!prediction.predicted() || (integrator->info().flags & kAdaptive)) continue;
    // rattle predicts Störmer–Verlet's limit for the tangent oscillation, but is for constrained
    // problems only: the harmonic search cannot run it.
    if (!applicable(*integrator, *make_problem("harmonic")).ok) continue;
    ++compared;
    const auto result = search("harmonic", spec, options);
    EXPECT_EQ(result.predicted, prediction.homega_limit) << spec;
    if (std::isinf(prediction.homega_limit)) {
      EXPECT_EQ(result.status, "stable_to_max") << spec;
    } else if (prediction.homega_limit == 0.0) {
      EXPECT_EQ(result.status, "unstable_at_min") << spec;
    } else {
      EXPECT_EQ(result.status, "bracketed") << spec;
      EXPECT_NEAR(result.homega_limit / prediction.homega_limit, 1.0, 2e-3) << spec;
    }
  }
  EXPECT_GE(compared, 15);
}

TEST(Stability, BadInputNamesTheKey) {
  StabilityOptions options = fast_options();
  options.homega_max = options.homega_min / 2;
  try {
    search("harmonic", "rk4", options);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("homega_max"), std::string::npos) << error.what();
  }
  EXPECT_THROW(search("harmonic", "cvode_bdf", fast_options()), InputError);
  options = fast_options();
  options.growth = 0.5;
  EXPECT_THROW(search("harmonic", "rk4", options), InputError);
}

// A scene with one [[stability]] block: parsed, run by the sweep, written to stability.csv.
TEST(StabilityScene, BlockIsParsedRunAndWritten) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(testing::TempDir()) / "geomint_stability_scene";
  fs::create_directories(dir);
  const std::string path = (dir / "scene.toml").string();
  std::ofstream(path) << "title = \"t\"\n[[stability]]\nlabel = \"s\"\nproblems = [\"harmonic\"]\n"
                         "methods = [\"stormer_verlet\"]\nhomega_max = 10.0\nperiods = 10.0\n"
                         "min_steps = 1000\nrel_tol = 1e-4\nquick_min_steps = 100\n";
  const Scene scene = load_scene(path, false);
  ASSERT_EQ(scene.stability.size(), 1u);
  EXPECT_EQ(scene.stability[0].options.min_steps, 1000);
  EXPECT_EQ(load_scene(path, true).stability[0].options.min_steps, 100);
  SweepOptions options;
  options.out_dir = dir.string();
  options.progress = false;
  EXPECT_EQ(run_sweep(scene, options), 0);
  std::ifstream csv(dir / "stability.csv");
  const std::string text((std::istreambuf_iterator<char>(csv)), std::istreambuf_iterator<char>());
  const auto rows = parse_csv(text);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_NEAR(std::stod(rows[0].at("homega_max_measured")), 2.0, 1e-3);
  EXPECT_EQ(rows[0].at("predicted"), "2");

  std::ofstream(path) << "title = \"t\"\n[[stability]]\nlabel = \"s\"\nproblems = [\"harmonic\"]\n"
                         "methods = [\"rk4\"]\nhomega_maks = 10.0\n";
  try {
    load_scene(path, false);
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("homega_maks"), std::string::npos) << error.what();
  }
  std::ofstream(path) << "title = \"t\"\n[[stability]]\nlabel = \"s\"\nproblems = [\"harmonic\"]\n"
                         "methods = [\"odeint_dopri5\"]\n";
  EXPECT_THROW(load_scene(path, false), InputError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace stability_test
}  // namespace geomint
