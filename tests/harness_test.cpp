// Harness unit tests: spec parsing, order fit with plateau rejection, drift slope, writers,
// scene validation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "harness/observers.hpp"
#include "harness/order.hpp"
#include "harness/paths.hpp"
#include "harness/run.hpp"
#include "harness/scene.hpp"
#include "harness/table.hpp"

namespace geomint {
namespace harness_test {
namespace {

TEST(Spec, ParsesNameAndValues) {
  const Spec spec = Spec::parse("hp:alpha=0.5, solver=minimize");
  EXPECT_EQ(spec.name, "hp");
  EXPECT_EQ(spec.values.at("alpha"), "0.5");
  EXPECT_EQ(spec.values.at("solver"), "minimize");
  EXPECT_TRUE(Spec::parse("rk4").values.empty());
}

TEST(Spec, RejectsMalformedText) {
  for (const char* text : {"", ":", "a:", "a:=1", "a:b", "a:b=", "a:b=1,b=2", "a b"}) {
    EXPECT_THROW(Spec::parse(text), InputError) << text;
  }
}

TEST(Params, CanonicalFormSortsKeysAndFillsDefaults) {
  Params params(Spec::parse("m:zeta=2"), "test");
  params.real("zeta", 1.0, "");
  params.real("alpha", 0.25, "");
  params.finish();
  EXPECT_EQ(params.canonical(), "m:alpha=0.25,zeta=2");
}

TEST(Params, UnknownKeyListsValidOnes) {
  Params params(Spec::parse("m:bogus=1"), "method 'm'");
  params.real("alpha", 0.5, "");
  try {
    params.finish();
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("bogus"), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("alpha"), std::string::npos);
  }
}

// error = C dt^p exactly: the fit recovers p to round-off.
TEST(OrderFit, RecoversExactPowerLaw) {
  std::vector<double> dts, errors;
  for (int k = 0; k < 6; ++k) {
    dts.push_back(0.1 / (1 << k));
    errors.push_back(3.0 * std::pow(dts.back(), 2));
  }
  const OrderFit fit = fit_order(dts, errors);
  EXPECT_NEAR(fit.order, 2.0, 1e-12);
  EXPECT_EQ(fit.used.size(), 6u);
}

TEST(OrderFit, DropsRoundOffPlateauAndPreAsymptoticPoints) {
  // Order 4 in the middle, a pre-asymptotic first point, and a plateau at 3e-8 (last point).
  const std::vector<double> dts = {0.8, 0.4, 0.2, 0.1, 0.05, 0.025, 0.0125, 0.00625};
  std::vector<double> errors;
  for (double dt : dts) errors.push_back(std::max(dt * dt * dt * dt, 3e-8));
  errors[0] = 5.0;  // pre-asymptotic: far above the power law
  const OrderFit fit = fit_order(dts, errors);
  ASSERT_TRUE(std::isfinite(fit.order)) << fit.note;
  EXPECT_NEAR(fit.order, 4.0, 0.05) << fit.note;
  EXPECT_EQ(fit.used.front(), 1);
  EXPECT_LT(fit.used.back(), 7);
  EXPECT_NE(fit.note.find("plateau"), std::string::npos);
}

TEST(OrderFit, NeedsThreePoints) {
  const OrderFit fit = fit_order({0.1, 0.05, 0.025}, {1e-3, NAN, 1e-20});
  EXPECT_TRUE(std::isnan(fit.order));
  EXPECT_NE(fit.note.find("need 3"), std::string::npos);
}

// Errors that have saturated at the size of the solution follow a clean power law of their own
// (Kepler at e = 0.999: 1.1e4, 5.6e3, 2.8e3, 1.4e3 gave "order 0.999"): above the ceiling they are
// not asymptotic, and with fewer than three points left there is no fit.
TEST(OrderFit, ErrorsAboveTheSolutionScaleAreNotAsymptotic) {
  const std::vector<double> dts = {0.01, 0.005, 0.0025, 0.00125};
  const std::vector<double> errors = {11179.0, 5589.3, 2795.1, 1399.3};
  EXPECT_NEAR(fit_order(dts, errors).order, 1.0, 0.01);
  const OrderFit fit = fit_order(dts, errors, 1e-13, 4.47);
  EXPECT_TRUE(std::isnan(fit.order));
  EXPECT_NE(fit.note.find("4 with error above 4.47"), std::string::npos) << fit.note;
  // Below the ceiling the points stay: the first two are dropped, the rest fit.
  const std::vector<double> mixed = {5.0, 2.0, 1e-2, 2.5e-3, 6.25e-4, 1.5625e-4};
  const std::vector<double> ladder = {0.8, 0.4, 0.2, 0.1, 0.05, 0.025};
  const OrderFit kept = fit_order(ladder, mixed, 1e-13, 1.0);
  ASSERT_TRUE(std::isfinite(kept.order)) << kept.note;
  EXPECT_NEAR(kept.order, 2.0, 1e-9);
  EXPECT_EQ(kept.used.front(), 2);
}

TEST(Drift, LeastSquaresSlope) {
  EXPECT_NEAR(least_squares_slope({1, 2, 3, 4}, {2, 4, 6, 8}), 2.0, 1e-14);
  EXPECT_NEAR(least_squares_slope({1, 2, 3, 4}, {5, 5, 5, 5}), 0.0, 1e-14);
}

TEST(Table, CsvHasProvenanceHeaderAndQuotes) {
  const std::vector<Row> rows = {{{"method", "hp:alpha=0.5,solver=newton"}, {"dt", "0.1"}},
                                 {{"dt", "0.2"}, {"wall_s", "1"}}};
  const auto columns = column_union(rows, standard_columns());
  EXPECT_EQ(columns, (std::vector<std::string>{"method", "dt", "wall_s"}));
  const std::string csv = to_csv(rows, columns, {{"geomint", "test"}});
  EXPECT_EQ(csv,
            "# geomint: test\nmethod,dt,wall_s\n\"hp:alpha=0.5,solver=newton\",0.1,\n,0.2,1\n");
}

TEST(Table, ParseCsvRoundTripsToCsv) {
  const std::vector<Row> rows = {{{"method", "hp:alpha=0.5,solver=newton"}, {"dt", "0.1"}},
                                 {{"dt", "0.2"}, {"wall_s", "1"}, {"message", "say \"no\""}}};
  const auto columns = column_union(rows, standard_columns());
  EXPECT_EQ(parse_csv(to_csv(rows, columns, {{"geomint", "test"}})), rows);
  EXPECT_THROW(parse_csv("a,b\n1,2,3\n"), std::runtime_error);
}

// docs/DESIGN.md §5: numbers are written with enough digits to round-trip. Every metric of a run
// row, read back as text, must give the very double the observers computed (a fixed 6- or 15-digit
// format would lose bits of energy_err_max, error_final, ... and of every gate built on them).
TEST(Table, RunRowMetricsRoundTripExactly) {
  RunConfig config;
  config.dt = 0.0123;
  config.t_end = 3.7;
  config.timing_repeats = 0;
  const RunResult result = run_one("kepler:e=0.6", "stormer_verlet", config);
  ASSERT_TRUE(result.ok);
  ASSERT_GE(result.record.metrics.size(), 5u);
  const Row row = to_row(result.record);
  for (const auto& [column, value] : result.record.metrics) {
    ASSERT_TRUE(row.count(column)) << column;
    const std::string& text = row.at(column);
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), value) << column << " written as " << text;
  }
  EXPECT_EQ(std::strtod(row.at("dt").c_str(), nullptr), config.dt);
  EXPECT_EQ(std::strtod(row.at("t_end").c_str(), nullptr), config.t_end);
}

TEST(Table, AtomicWriteLeavesNoTemporaryFile) {
  const auto dir = std::filesystem::temp_directory_path() / "geomint_atomic_test";
  std::filesystem::remove_all(dir);
  write_file_atomic((dir / "a.csv").string(), "x\n");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "a.csv");
  }
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(Scene, SanitizesSpecsForFileNames) {
  EXPECT_EQ(sanitize_for_path("hp:alpha=0.5,solver=minimize"), "hp_alpha_0.5_solver_minimize");
}

std::string write_scene(const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / "geomint_scene_test.toml";
  std::ofstream(path) << text;
  return path.string();
}

void expect_scene_error(const std::string& text, const std::string& needle) {
  try {
    load_scene(write_scene(text), false);
    FAIL() << "no error for: " << text;
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
  }
}

TEST(Scene, RejectsBadFiles) {
  const std::string good_block =
      "[[runs]]\nlabel='a'\nproblems=['harmonic']\nmethods=['rk4']\ndt=0.1\nt_end=1.0\n";
  expect_scene_error("title = \n", "malformed");
  expect_scene_error(good_block, "title");
  expect_scene_error("title='x'\n", "nothing to run");
  expect_scene_error("title='x'\n[[runs]]\nlabel='a'\nmethods=['rk4']\ndt=0.1\nt_end=1.0\n",
                     "problems");
  expect_scene_error("title='x'\n" + good_block + "colour='red'\n", "colour");
  expect_scene_error(
      "title='x'\n[[runs]]\nlabel='a'\nproblems=['harmonic']\nmethods=['nope']\n"
      "dt=0.1\nt_end=1.0\n",
      "nope");
  expect_scene_error(
      "title='x'\n[[runs]]\nlabel='a'\nproblems=['harmonic']\nmethods=['rk4']\n"
      "dt=-0.1\nt_end=1.0\n",
      "dt");
  expect_scene_error(
      "title='x'\n[[runs]]\nlabel='a'\nproblems=['harmonic']\nmethods=['rk4']\n"
      "dt='big'\nt_end=1.0\n",
      "dt");
  expect_scene_error(
      "title='x'\n[[orders]]\nlabel='a'\nproblems=['harmonic']\nmethods=['rk4']\n"
      "dt0=0.1\nlevels=2\nt_end=1.0\n",
      "levels");
  EXPECT_NO_THROW(load_scene(write_scene("title='x'\n" + good_block), false));
}

}  // namespace
}  // namespace harness_test
}  // namespace geomint
