// The JSON of a table (to_json, docs/USAGE.md "JSON tables"): strict JSON however odd its text
// (control characters, invalid UTF-8), numbers with the CSV's digits, non-finite cells as words,
// empty cells as null, column types; and parse_table_format's refusal of other formats.
#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "harness/table.hpp"
#include "problems/spec.hpp"

namespace geomint {
namespace table_json_test {
namespace {

CsvTable odd_table() {
  CsvTable table;
  table.provenance = {{"command", "geomint run --out 'a\tb\x01\x1f\x7f\"\\c\xff\xfe.json'"},
                      {"date", "2026-01-01T00:00:00Z"},
                      {"command", "a second value is dropped"}};
  table.columns = {"label", "dt", "energy_err_max", "message", "steps"};
  table.rows = {{{"label", "x\ny\xc3"}, {"dt", "0.1"}, {"energy_err_max", "nan"}, {"steps", "10"}},
                {{"label", "1"}, {"dt", "1e-05"}, {"energy_err_max", "-inf"}, {"steps", "-0"}},
                {{"dt", "2.2250738585072014e-308"}, {"energy_err_max", "0.30000000000000004"}}};
  return table;
}

TEST(TableJson, OddTextIsStrictJson) {
  const std::string text = to_json(odd_table());
  // nlohmann's parser refuses raw control characters and ill-formed UTF-8 in strings.
  const auto document = nlohmann::json::parse(text);
  EXPECT_EQ(document["provenance"]["command"],
            "geomint run --out 'a\tb\x01\x1f\x7f\"\\c\xEF\xBF\xBD\xEF\xBF\xBD.json'");
  EXPECT_EQ(document["provenance"].size(), 2u);
  EXPECT_EQ(document["rows"][0]["label"], "x\ny\xEF\xBF\xBD");
  for (const char raw : {'\t', '\x01', '\x1f', '\x7f'}) {
    EXPECT_EQ(text.find(raw), std::string::npos) << static_cast<int>(raw);
  }
}

TEST(TableJson, CellsKeepTheCsvDigitsTypesAndNulls) {
  const auto document = nlohmann::json::parse(to_json(odd_table()));
  EXPECT_EQ(document["columns"],
            nlohmann::json::array({"label", "dt", "energy_err_max", "message", "steps"}));
  EXPECT_EQ(document["types"]["label"], "string");  // "x\ny" is no number
  EXPECT_EQ(document["types"]["dt"], "number");
  EXPECT_EQ(document["types"]["energy_err_max"], "number");
  EXPECT_EQ(document["types"]["message"], "string");  // no cell at all: no number either
  const auto& rows = document["rows"];
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1]["label"], "1");  // a string column keeps "1" a string
  EXPECT_TRUE(rows[2]["label"].is_null());
  EXPECT_TRUE(rows[0]["message"].is_null());
  EXPECT_EQ(rows[0]["energy_err_max"], "nan");
  EXPECT_EQ(rows[1]["energy_err_max"], "-inf");
  const auto bits = [](double value) { return std::bit_cast<std::uint64_t>(value); };
  EXPECT_EQ(bits(rows[2]["dt"].get<double>()), bits(2.2250738585072014e-308));
  EXPECT_EQ(bits(rows[2]["energy_err_max"].get<double>()), bits(0.1 + 0.2));
  EXPECT_EQ(bits(rows[1]["dt"].get<double>()), bits(1e-05));
  for (const auto& row : rows) EXPECT_EQ(row.size(), 5u);  // every row has every column
}

TEST(TableJson, TextThatIsNoJsonNumberMakesAStringColumn) {
  for (const char* cell : {"+1", ".5", "1.", "01", "0x10", "1e", "Infinity", "NaN", " 1"}) {
    CsvTable table;
    table.columns = {"v"};
    table.rows = {{{"v", "2"}}, {{"v", cell}}};
    const auto document = nlohmann::json::parse(to_json(table));
    EXPECT_EQ(document["types"]["v"], "string") << cell;
    EXPECT_EQ(document["rows"][1]["v"], cell);
    EXPECT_EQ(document["rows"][0]["v"], "2");
  }
}

TEST(TableJson, NonFiniteWordsAloneAreText) {
  CsvTable table;
  table.columns = {"status", "energy_drift"};
  table.rows = {{{"status", "nan"}, {"energy_drift", "-nan"}}, {{"energy_drift", "1.5"}}};
  const auto document = nlohmann::json::parse(to_json(table));
  EXPECT_EQ(document["types"]["status"], "string");
  EXPECT_EQ(document["types"]["energy_drift"], "number");
  EXPECT_EQ(document["rows"][0]["status"], "nan");
  EXPECT_EQ(document["rows"][0]["energy_drift"], "-nan");
  EXPECT_EQ(document["rows"][1]["energy_drift"], 1.5);
}

TEST(TableJson, EmptyTableIsAnEmptyDocument) {
  const auto document = nlohmann::json::parse(to_json(CsvTable{}));
  EXPECT_TRUE(document["provenance"].empty());
  EXPECT_TRUE(document["columns"].empty());
  EXPECT_TRUE(document["rows"].empty());
}

TEST(TableJson, ProvenanceLineIsOneLine) {
  EXPECT_EQ(provenance_line("command", "geomint run --out 'a\nb\rc'"),
            "# command: geomint run --out 'a b c'\n");
  const CsvTable read = parse_csv_table(to_csv({{{"x", "1"}}}, {"x"}, {{"command", "a\nb,c"}}), "");
  EXPECT_EQ(read.columns, std::vector<std::string>{"x"});
  EXPECT_EQ(read.value("command"), "a b,c");
}

TEST(TableJson, FormatsAreCsvAndJson) {
  EXPECT_EQ(parse_table_format("csv", "--format"), TableFormat::kCsv);
  EXPECT_EQ(parse_table_format("json", "--format"), TableFormat::kJson);
  for (const char* other : {"xml", "JSON", "", "csv "}) {
    try {
      parse_table_format(other, "--format");
      ADD_FAILURE() << other;
    } catch (const InputError& error) {
      EXPECT_NE(std::string(error.what()).find("(allowed: csv, json)"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace table_json_test
}  // namespace geomint
