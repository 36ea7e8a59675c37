// The run record's column schema (harness/record.hpp, docs/DESIGN.md §5): one spelling and one
// place in the table per column, unknown metrics rejected, tables list only the columns set.
#include "harness/record.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>

#include "harness/observers.hpp"
#include "problems/problem.hpp"

namespace geomint {
namespace record_test {
namespace {

std::vector<std::string> schema_names() {
  std::vector<std::string> names;
  for (const auto& column : record_schema()) names.push_back(column.name);
  return names;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// The schema lists the standard columns in standard_columns() order, then only the columns
// some tables have; so a record table reads like every other geomint CSV.
TEST(RunRecord, SchemaFollowsTheStandardColumnOrder) {
  const auto names = schema_names();
  std::vector<std::string> standard_in_schema, schema_in_standard;
  for (const auto& name : standard_columns()) {
    if (contains(names, name)) standard_in_schema.push_back(name);
  }
  for (const auto& name : names) {
    if (contains(standard_columns(), name)) {
      schema_in_standard.push_back(name);
    } else {
      EXPECT_TRUE(name == "order_level" || name == "reference") << name;
    }
  }
  EXPECT_EQ(schema_in_standard, standard_in_schema);
  EXPECT_EQ(names.back(), "reference");
}

TEST(RunRecord, MetricWithoutAColumnIsRejected) {
  RunRecord record;
  record.problem = "harmonic";
  record.method = "stormer_verlet";
  record.status = "ok";
  record.metrics["energy_error_max"] = 1.0;  // a second spelling of energy_err_max
  EXPECT_THROW(to_row(record), std::logic_error);
}

// Every metric an observer reports, on every registered problem, has its column. The observers
// see the exact solution where there is one (so the phase and perihelion metrics are produced),
// else the initial state at the sample times.
TEST(RunRecord, EveryObserverMetricHasAColumn) {
  constexpr int kSamples = 400;
  std::set<std::string> seen;
  for (const auto& spec : problem_test_specs()) {
    const auto problem = make_problem(spec);
    const State initial = problem->initial_state();
    const double t_end = problem->default_t_end();
    auto observers = make_metric_observers(*problem);
    for (auto& observer : observers) observer->begin(*problem, initial, t_end);
    for (int i = 1; i <= kSamples; ++i) {
      const double t = initial.t + t_end * i / kSamples;
      State state = problem->has(kExact) ? problem->exact(t) : initial;
      state.t = t;
      for (auto& observer : observers) observer->observe(*problem, state);
    }
    RunRecord record;
    for (const auto& observer : observers) observer->finish(record.metrics);
    for (const auto& [name, value] : record.metrics) seen.insert(name);
    EXPECT_NO_THROW(to_row(record)) << spec;
  }
  // The trajectories above reach the phase and perihelion observers, not only the cheap ones.
  EXPECT_TRUE(seen.count("period_err"));
  EXPECT_TRUE(seen.count("perihelion_err"));
}

TEST(RunRecord, TablesListOnlyTheColumnsSomeRecordSets) {
  RunRecord failed;
  failed.label = "a";
  failed.problem = "harmonic";
  failed.method = "x";
  failed.status = "error";
  failed.message = "";  // set, though empty: the column is listed
  RunRecord run;
  run.problem = "harmonic";
  run.method = "rk4";
  run.dt = 0.1;
  run.t_end = 1;
  run.status = "ok";
  run.steps = 10;
  run.metrics["energy_err_max"] = 0.25;
  run.counters = Counters{};
  run.counters->force_evals = 40;
  const std::vector<std::string> expected = {
      "label",          "problem",       "method",         "dt",
      "t_end",          "status",        "message",        "steps",
      "energy_err_max", "force_evals",   "energy_evals",   "hessian_evals",
      "newton_iters",   "linear_solves", "factorizations", "rejected"};
  EXPECT_EQ(record_columns({failed, run}), expected);
  const Row row = to_row(run);
  EXPECT_EQ(row.at("dt"), "0.1");
  EXPECT_EQ(row.at("steps"), "10");
  EXPECT_EQ(row.at("energy_err_max"), "0.25");
  EXPECT_EQ(row.at("force_evals"), "40");
  EXPECT_FALSE(row.count("message"));
  EXPECT_EQ(to_row(failed).at("message"), "");
}

// A study that ran lists every fit column, empty when there is no fit; one that threw lists
// none of them (order.csv keeps the layout of the former generic rows).
TEST(OrderRecord, FitColumnsOnlyForStudiesThatRan) {
  OrderRecord no_fit;
  no_fit.problem = "harmonic";
  no_fit.method = "rk4";
  no_fit.ran = true;
  no_fit.declared_order = 4;
  no_fit.status = "no_fit";
  no_fit.t_end = 2;
  OrderRecord fitted = no_fit;
  fitted.order = 3.99951;
  fitted.points_used = {0.1, 0.05, 0.025};
  fitted.status = "ok";
  OrderRecord failed;
  failed.problem = "harmonic";
  failed.method = "rk5";
  failed.status = "error";
  failed.message = "unknown method";
  const Row row = to_row(no_fit);
  EXPECT_EQ(row.at("order"), "");
  EXPECT_EQ(row.at("points_used"), "");
  EXPECT_EQ(row.at("declared_order"), "4");
  EXPECT_EQ(to_row(fitted).at("order"), "4.000");
  EXPECT_EQ(to_row(fitted).at("points_used"), "0.1 0.05 0.025");
  EXPECT_EQ(columns_of(order_schema(), std::vector<OrderRecord>{failed}),
            (std::vector<std::string>{"problem", "method", "status", "message"}));
  EXPECT_EQ(columns_of(order_schema(), std::vector<OrderRecord>{failed, no_fit}),
            (std::vector<std::string>{"problem", "method", "order", "order_q", "order_p",
                                      "order_multiplier", "declared_order", "points_used", "status",
                                      "message", "t_end"}));
  // The multiplier's order is n/a where the problem knows no exact multiplier, empty without a fit.
  EXPECT_EQ(row.at("order_multiplier"), "n/a");
  OrderRecord constrained = fitted;
  constrained.multiplier_applies = true;
  EXPECT_EQ(to_row(constrained).at("order_multiplier"), "");
  constrained.order_multiplier = 1.9912;
  constrained.order_q = 2.0004;
  EXPECT_EQ(to_row(constrained).at("order_multiplier"), "1.991");
  EXPECT_EQ(to_row(constrained).at("order_q"), "2.000");
}

}  // namespace
}  // namespace record_test
}  // namespace geomint
