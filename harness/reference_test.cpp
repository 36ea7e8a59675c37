// Reference solutions: the generator reproduces exact solutions to its own error
// estimate, the harness measures errors against a reference file and names it, and missing or
// malformed files are InputErrors that name the file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "harness/reference_generator.hpp"
#include "harness/run.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace reference_test {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("geomint_reference_" + std::to_string(::getpid()) + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Writes the reference into `dir` and returns its summary.
ReferenceSummary generate(const std::string& problem_spec, double t_end, double every,
                          const std::filesystem::path& dir, double dt = 0) {
  ReferenceOptions options;
  options.problem_spec = problem_spec;
  options.t_end = t_end;
  options.output_every = every;
  options.dt = dt;
  options.out_path = reference_path(dir.string(), *make_problem(problem_spec));
  options.command_line = "reference_test";
  return generate_reference(options);
}

class ExactProblem : public testing::TestWithParam<const char*> {};

TEST_P(ExactProblem, ReferenceMatchesTheExactSolutionToItsEstimatedError) {
  const std::string spec = GetParam();
  const auto dir = temp_dir("exact");
  const ReferenceSummary summary = generate(spec, 20.0, 1.0, dir);
  const auto problem = make_problem(spec);
  const auto reference = load_reference(summary.path, *problem);
  ASSERT_EQ(reference->times.size(), 21u);
  EXPECT_EQ(reference->problem_spec, problem->spec());
  EXPECT_DOUBLE_EQ(reference->times.back(), 20.0);
  // The estimate (difference to the 2·dt run) is ~64x the order-6 error of the written run; it
  // must still be small enough to serve as a reference for the work-precision errors.
  EXPECT_LT(reference->estimated_error, 1e-9) << spec;
  double worst = 0;
  for (size_t k = 0; k < reference->times.size(); ++k) {
    const State exact = problem->exact(reference->times[k]);
    const double error = std::sqrt((reference->q[k] - exact.q).squaredNorm() +
                                   (reference->p[k] - exact.p).squaredNorm());
    worst = std::max(worst, error);
  }
  // Floor 1e-13: the exact solutions themselves are double-precision evaluations.
  EXPECT_LE(worst, std::max(reference->estimated_error, 1e-13))
      << spec << ": estimated " << reference->estimated_error;
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Problems, ExactProblem,
                         // The general (non-separable) kind too: q' = v(q, p), not M⁻¹p.
                         testing::Values("pendulum:theta0=1.5", "kepler:e=0.6",
                                         "kepler:coordinates=polar,e=0.6",
                                         "spherical_pendulum:coordinates=angles,length=1.7,"
                                         "mass=0.6,gravity=2.3,theta0=0.9"),
                         [](const testing::TestParamInfo<const char*>& info) {
                           std::string name = info.param;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

// A spec longer than a file name may be (rod_chain:n=64 lists its 64 angles) still has a
// reference path: a readable prefix and a hash, distinct for distinct specs (it was an internal
// error, "File name too long", in every run of such a problem).
TEST(Reference, LongSpecsHaveShortDistinctPaths) {
  const std::string a = reference_path("dir", *make_problem("rod_chain:n=64"));
  const std::string b = reference_path("dir", *make_problem("rod_chain:n=64,theta=1.5"));
  EXPECT_LE(std::filesystem::path(a).filename().string().size(), 255u);
  EXPECT_NE(a, b);
  EXPECT_EQ(a, reference_path("dir", *make_problem("rod_chain:n=64")));
  EXPECT_EQ(reference_path("dir", *make_problem("kepler:e=0.6")), "dir/kepler_e_0.6.csv");
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 0.02;
  EXPECT_TRUE(run_one("rod_chain:n=64", "rattle", config).ok);
}

// A small free spring network: no exact solution, so the harness looks for a reference.
const char* kNoExact = "spring_net:nx=2,ny=2";

TEST(Harness, UsesTheReferenceFileAndNamesIt) {
  const auto dir = temp_dir("harness");
  const ReferenceSummary summary = generate(kNoExact, 2.0, 0.5, dir, 0.0025);
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 2.0;
  config.timing_repeats = 0;
  config.reference_dir = dir.string();
  const RunResult coarse = run_one(kNoExact, "stormer_verlet", config);
  ASSERT_TRUE(coarse.ok) << coarse.record.message.value_or("");
  EXPECT_EQ(coarse.record.reference.value_or(""),
            std::filesystem::path(summary.path).filename().string());
  ASSERT_TRUE(coarse.record.metrics.count("error_final"));
  ASSERT_TRUE(coarse.record.metrics.count("error_max"));

  // error_final is the distance to the reference's last row.
  const auto problem = make_problem(kNoExact);
  const auto reference = load_reference(summary.path, *problem);
  const double direct = std::sqrt((coarse.final_state.q - reference->q.back()).squaredNorm() +
                                  (coarse.final_state.p - reference->p.back()).squaredNorm());
  EXPECT_DOUBLE_EQ(coarse.record.metrics.at("error_final"), direct);
  EXPECT_GE(coarse.record.metrics.at("error_max"), coarse.record.metrics.at("error_final"));

  // Stormer-Verlet's second order shows against the reference: halving dt quarters the error.
  config.dt = 0.005;
  const RunResult fine = run_one(kNoExact, "stormer_verlet", config);
  const double ratio =
      coarse.record.metrics.at("error_final") / fine.record.metrics.at("error_final");
  EXPECT_NEAR(ratio, 4.0, 0.4);
  EXPECT_LT(reference->estimated_error, 1e-3 * fine.record.metrics.at("error_final"));

  // A horizon the reference has no row for: no error columns, no reference column.
  config.t_end = 1.7;
  const RunResult off_grid = run_one(kNoExact, "stormer_verlet", config);
  EXPECT_FALSE(off_grid.record.metrics.count("error_final"));
  EXPECT_FALSE(off_grid.record.reference.has_value());

  // No reference file: no error columns.
  config.t_end = 2.0;
  config.reference_dir = (dir / "empty").string();
  const RunResult without = run_one(kNoExact, "stormer_verlet", config);
  EXPECT_FALSE(without.record.metrics.count("error_final"));
  EXPECT_FALSE(without.record.reference.has_value());
  std::filesystem::remove_all(dir);
}

// Expects InputError whose message contains every fragment.
void expect_input_error(const std::function<void()>& action,
                        const std::vector<std::string>& fragments) {
  try {
    action();
    ADD_FAILURE() << "no InputError";
  } catch (const InputError& error) {
    for (const auto& fragment : fragments) {
      EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
          << error.what() << " lacks '" << fragment << "'";
    }
  }
}

TEST(Reference, MissingOrMalformedFilesAreInputErrorsNamingTheFile) {
  const auto dir = temp_dir("bad");
  const auto problem = make_problem(kNoExact);
  const std::string missing = (dir / "missing.csv").string();
  expect_input_error([&] { load_reference(missing, *problem); }, {missing, "cannot be read"});

  const ReferenceSummary summary = generate(kNoExact, 1.0, 0.5, dir, 0.01);
  std::stringstream original;
  original << std::ifstream(summary.path).rdbuf();
  const std::string good = original.str();
  auto corrupt = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(summary.path) << text;
  };
  // A number mangled in the last row.
  std::ofstream(summary.path) << good.substr(0, good.rfind(',') + 1) << "abc\n";
  expect_input_error([&] { load_reference(summary.path, *problem); },
                     {summary.path, "not a finite number"});
  // The harness refuses it as well instead of skipping it.
  RunConfig config;
  config.dt = 0.01;
  config.t_end = 1.0;
  config.timing_repeats = 0;
  config.reference_dir = dir.string();
  expect_input_error([&] { run_one(kNoExact, "stormer_verlet", config); }, {summary.path});
  // Another problem's file.
  corrupt("# reference_problem: ", "# reference_problem: x");
  expect_input_error([&] { load_reference(summary.path, *problem); },
                     {summary.path, "is for problem"});
  // No error estimate.
  corrupt("# estimated_error_max: ", "# estimated: ");
  expect_input_error([&] { load_reference(summary.path, *problem); }, {"estimated_error_max"});
  std::filesystem::remove_all(dir);
}

TEST(Reference, BadOptionsAreInputErrors) {
  ReferenceOptions options;
  options.problem_spec = "kepler:e=0.6";
  options.t_end = 10.0;
  options.output_every = 3.0;
  expect_input_error([&] { generate_reference(options); }, {"--every"});
  options.output_every = 1.0;
  options.t_end = -1.0;
  expect_input_error([&] { generate_reference(options); }, {"--t-end"});
  // A first-order-only problem has no (q, p, ∇V) to integrate (it segfaulted before).
  options.problem_spec = "robertson";
  options.t_end = 10.0;
  expect_input_error([&] { generate_reference(options); }, {"'robertson'", "first-order"});
  // Constrained problems: the generator would drop the constraint forces.
  options.problem_spec = "rod_chain:n=2";
  expect_input_error([&] { generate_reference(options); }, {"'rod_chain'", "constraints"});
  options.problem_spec = "no_such_problem";
  EXPECT_THROW(generate_reference(options), InputError);
}

}  // namespace
}  // namespace reference_test
}  // namespace geomint
