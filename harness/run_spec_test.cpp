// RunSpec (harness/run_spec.hpp): validate() lists every error of a run's inputs at once, each
// naming its option; a MethodFactory's integrators run bit for bit as make_integrator's; and
// run_one(RunSpec) gives the record the spec-string form gives.
#include "harness/run_spec.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace geomint {
namespace run_spec_test {
namespace {

bool mentions(const std::vector<std::string>& errors, const std::string& fragment) {
  for (const auto& error : errors) {
    if (error.find(fragment) != std::string::npos) return true;
  }
  return false;
}

TEST(RunSpec, ValidateListsEveryErrorAtOnce) {
  RunConfig config;
  config.dt = -0.3;
  config.t_end = 0;
  config.series_every = 0;
  config.timing_repeats = kMaxTimingRepeats + 1;
  config.diverge_factor = -2;
  config.max_steps = 0;
  config.series_path = std::filesystem::temp_directory_path().string();  // a folder, not a file
  // rattle needs holonomic constraints, which the pendulum in its angle has none of.
  const RunSpec spec = RunSpec::parse("pendulum:theta0=0.7", "rattle", config);
  const std::vector<std::string> errors = spec.validate();
  for (const char* option : {"--dt", "--t-end", "--every", "--timing-repeats", "--diverge-factor",
                             "--max-steps", "--series", "rattle"}) {
    EXPECT_TRUE(mentions(errors, option)) << option << " missing from " << errors.size();
  }
  // One message per error: --t-end/--dt is not judged while either term is invalid.
  EXPECT_EQ(errors.size(), 8u);
  try {
    throw_input_errors(errors);
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    for (const auto& message : errors) {
      EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << message;
    }
  }
  EXPECT_THROW(run_one(spec), InputError);
}

TEST(RunSpec, ValidSpecHasNoErrorAndTheSectionIsChecked) {
  RunConfig config;
  config.dt = 0.07;
  config.t_end = 1.4;
  RunSpec spec = RunSpec::parse("harmonic:omega=3,mass=2", "stormer_verlet", config);
  EXPECT_TRUE(spec.validate().empty());
  // A Poincaré section needs a coordinate of the problem: index 1 of a 1-dof oscillator is none.
  spec.config.series_path = (std::filesystem::temp_directory_path() / "run_spec_s.csv").string();
  spec.config.series_section = 1;
  const std::vector<std::string> errors = spec.validate();
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("series_section = 1"), std::string::npos) << errors[0];
}

TEST(RunSpec, ParseStopsAtAnUnknownName) {
  EXPECT_THROW(RunSpec::parse("no_such_problem", "rk4", {}), InputError);
  EXPECT_THROW(RunSpec::parse("kepler", "rk4:no_such_key=1", {}), InputError);
}

// Fresh integrators from the factory (parsed once) take the steps make_integrator's take, to the
// bit, for a method with parameters (canonical spec) and a wrapper around a base method.
TEST(MethodFactory, FreshIntegratorsMatchTheRegistryBitForBit) {
  const auto problem = parse_problem("pendulum:theta0=1.3,omega0=1.7");
  for (const std::string text : {"hp:alpha=0.3", "composition:base=stormer_verlet", "rk4"}) {
    const MethodFactory factory(text);
    EXPECT_EQ(factory.spec(), make_integrator(text)->spec());
    EXPECT_EQ(factory.info().name, make_integrator(text)->info().name);
    State from_factory = problem->initial_state(), from_registry = from_factory;
    for (int run = 0; run < 2; ++run) {  // the second run must not inherit the first's state
      auto a = factory.make();
      auto b = make_integrator(text);
      EXPECT_EQ(a->spec(), factory.spec());
      from_factory = from_registry = problem->initial_state();
      a->reset(*problem, from_factory, 0.037);
      b->reset(*problem, from_registry, 0.037);
      for (int k = 0; k < 25; ++k) {
        ASSERT_TRUE(a->step(*problem, from_factory, 0.037).ok) << text;
        ASSERT_TRUE(b->step(*problem, from_registry, 0.037).ok) << text;
      }
      EXPECT_EQ(from_factory.q, from_registry.q) << text;
      EXPECT_EQ(from_factory.p, from_registry.p) << text;
      EXPECT_EQ(a->counters().force_evals, b->counters().force_evals) << text;
    }
  }
}

TEST(RunSpec, RunOneOfObjectsMatchesTheSpecStringForm) {
  RunConfig config;
  config.dt = 0.013;
  config.t_end = 0.91;
  config.timing_repeats = 1;
  const RunResult from_strings = run_one("kepler:e=0.4", "gauss:s=2", config);
  const RunResult from_objects = run_one(RunSpec::parse("kepler:e=0.4", "gauss:s=2", config));
  EXPECT_EQ(from_objects.record.method, from_strings.record.method);
  EXPECT_EQ(from_objects.record.problem, from_strings.record.problem);
  EXPECT_EQ(from_objects.record.metrics, from_strings.record.metrics);
  EXPECT_EQ(from_objects.final_state.q, from_strings.final_state.q);
  EXPECT_EQ(from_objects.record.steps, 70);
  ASSERT_TRUE(from_objects.record.wall_s_repeats.has_value());
  EXPECT_EQ(*from_objects.record.wall_s_repeats, 1);
}

}  // namespace
}  // namespace run_spec_test
}  // namespace geomint
