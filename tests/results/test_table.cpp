// The one table writer of every verb (results/io/table.h): aligned text, CSV (RFC 4180), JSON.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "results/io/csv.h"
#include "results/io/table.h"

using namespace gravsweep::results;

namespace {

const std::string kAwkward = "rebound, then \"rest\"\nat 12 mm";  // a comma, a quote, a line break

Table awkward_table() {
  Table t({"trial_id", "note", "zstop_mm"});
  t.add({"T1", kAwkward, "12.5"});
  t.add({"T2", "plain", "-"});
  return t;
}

}  // namespace

// RFC 4180: CRLF after each record, the awkward field in quotes with its quote doubled; the
// campaign reader reads the same cells back.
TEST(TableWriter, CsvIsRfc4180AndReadsBack) {
  const std::string csv = awkward_table().csv();
  EXPECT_EQ(csv,
            "trial_id,note,zstop_mm\r\n"
            "T1,\"rebound, then \"\"rest\"\"\nat 12 mm\",12.5\r\n"
            "T2,plain,-\r\n");
  std::istringstream in(csv);
  CsvReader r(in);
  std::vector<std::string> f;
  int line = 0;
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"trial_id", "note", "zstop_mm"}));
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"T1", kAwkward, "12.5"}));
  ASSERT_TRUE(r.next(f, line));
  EXPECT_EQ(f, (std::vector<std::string>{"T2", "plain", "-"}));
  EXPECT_FALSE(r.next(f, line));
  EXPECT_EQ(awkward_table().render("csv"), csv);
}

// The same table as JSON: one object per row with the same values (numbers as numbers).
TEST(TableWriter, JsonParsesToTheSameValues) {
  const auto j = nlohmann::json::parse(awkward_table().render("json"));
  ASSERT_TRUE(j.is_array());
  ASSERT_EQ(j.size(), 2u);
  EXPECT_EQ(j[0]["trial_id"], "T1");
  EXPECT_EQ(j[0]["note"], kAwkward);
  EXPECT_EQ(j[0]["zstop_mm"], 12.5);
  EXPECT_EQ(j[1]["note"], "plain");
  EXPECT_EQ(j[1]["zstop_mm"], "-");
}

// Typed rows (the results verb): JSON keeps null, integers and strings that look like numbers as
// they are; CSV writes null as an empty cell.
TEST(TableWriter, TypedValuesKeepTheirTypeInJsonAndAreCellsInCsv) {
  Table t({"job_id", "n", "g", "missing"});
  t.add_values({"0012", 3, 1.62, nullptr});
  const auto j = nlohmann::json::parse(t.json());
  EXPECT_EQ(j[0]["job_id"], "0012");
  EXPECT_TRUE(j[0]["n"].is_number_integer());
  EXPECT_EQ(j[0]["g"], 1.62);
  EXPECT_TRUE(j[0]["missing"].is_null());
  EXPECT_EQ(t.csv(), "job_id,n,g,missing\r\n0012,3,1.62,\r\n");
}

// Aligned text: numbers right, text left, `-` (a missing value) leaves the alignment to the
// other cells; the queue verbs' look adds a rule, the model verbs' keeps the first column left.
TEST(TableWriter, TextAlignsNumbersRightAndRulesOnlyInTheRuledStyle) {
  Table plain({"g", "name", "value"});
  plain.add({"1.62", "moon", "-"});
  plain.add({"9.81", "earth", "12"});
  EXPECT_EQ(plain.render("table"),
            "g     name   value\n"
            "1.62  moon       -\n"
            "9.81  earth     12\n");
  Table ruled({"g", "name", "value"}, kRuledText);
  ruled.add({"1.62", "moon", "-"});
  ruled.add({"9.81", "earth", "12"});
  EXPECT_EQ(ruled.text(),
            "   g  name   value\n"
            "----  -----  -----\n"
            "1.62  moon       -\n"
            "9.81  earth     12\n");
  EXPECT_THROW((void)plain.render("xml"), std::invalid_argument);
}
