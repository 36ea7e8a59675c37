// The metric table (harness/metrics.hpp) is the one place a metric is named: the schema, the
// --metric list and the gates read it, so a metric declared there reaches every table and one
// missing from it is refused everywhere.
#include "harness/metrics.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "harness/record.hpp"
#include "harness/structure_metrics.hpp"
#include "harness/table.hpp"

namespace geomint {
namespace metrics_test {
namespace {

TEST(MetricTable, NamesAreUniqueAndFoundByName) {
  std::set<std::string> names;
  for (const MetricDecl* decl : metric_table()) {
    EXPECT_TRUE(names.insert(decl->key()).second) << decl->name << " declared twice";
    EXPECT_EQ(find_metric(decl->name), decl);
    EXPECT_FALSE(decl->computed_by.empty()) << decl->name;
  }
  EXPECT_EQ(find_metric("energy_error_max"), nullptr);
}

// A companion comes with an option that is in the table, so asking for that option is how its
// column is reached.
TEST(MetricTable, CompanionsBelongToAnOptionOfTheTable) {
  const auto& table = metric_table();
  for (const MetricDecl* decl : table) {
    if (decl->companion_of == nullptr) continue;
    EXPECT_EQ(decl->option_rank, 0) << decl->name << " is an option and a companion";
    EXPECT_GT(decl->companion_of->option_rank, 0) << decl->name;
    EXPECT_NE(std::find(table.begin(), table.end(), decl->companion_of), table.end()) << decl->name;
  }
}

// Every column has a writer: a row without an observer factory is written by the observer of a
// row above it, and no factory is declared twice (make_observers would call it twice).
TEST(MetricTable, EveryColumnComesAfterTheRowOfItsObserver) {
  const auto& table = metric_table();
  ASSERT_FALSE(table.empty());
  EXPECT_NE(table.front()->observer, nullptr) << table.front()->name;
  std::set<ObserverFactory> factories;
  for (const MetricDecl* decl : table) {
    if (decl->observer == nullptr) continue;
    EXPECT_TRUE(factories.insert(decl->observer).second) << decl->name;
  }
}

// The metric part of the standard columns is the table, in its order, between `steps` and
// `order`; the run record's schema writes those columns in that order.
TEST(MetricTable, StandardColumnsAndRecordSchemaComeFromTheTable) {
  const auto& standard = standard_columns();
  const auto first = std::find(standard.begin(), standard.end(), "steps") + 1;
  const auto last = std::find(standard.begin(), standard.end(), "order");
  ASSERT_LT(first, last);
  EXPECT_EQ(std::vector<std::string>(first, last), metric_names());
  std::vector<std::string> schema_metrics;
  for (const auto& column : record_schema()) {
    if (find_metric(column.name) != nullptr) schema_metrics.push_back(column.name);
  }
  EXPECT_EQ(schema_metrics, metric_names());
}

// `run --metric` accepts the options of the table, listed by rank (the help text's order), and
// nothing else: neither a companion nor a metric computed whenever it applies.
TEST(MetricTable, MetricOptionsAreTheDeclaredOptionsInRankOrder) {
  std::vector<std::string> expected;
  for (int rank = 1;; ++rank) {
    const auto& table = metric_table();
    const auto found = std::find_if(table.begin(), table.end(),
                                    [rank](const MetricDecl* d) { return d->option_rank == rank; });
    if (found == table.end()) break;
    expected.push_back((*found)->key());
  }
  EXPECT_EQ(optional_metric_names(), expected);
  size_t options = 0;
  for (const MetricDecl* decl : metric_table()) options += decl->option_rank > 0 ? 1 : 0;
  EXPECT_EQ(options, expected.size()) << "option ranks must be 1..N without gaps or repeats";
  EXPECT_THROW(check_optional_metrics({metric::period_err_rel.key()}, "--metric"), InputError);
  EXPECT_THROW(check_optional_metrics({metric::energy_err_max.key()}, "--metric"), InputError);
}

}  // namespace
}  // namespace metrics_test
}  // namespace geomint
