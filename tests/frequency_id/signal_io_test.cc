#include "frequency_id/signal_io.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace rmhb::frequency_id {
namespace {

CsvReadResult Parse(const std::string& text, Signal* signal,
                    const CsvReadOptions& options = CsvReadOptions()) {
  std::istringstream input(text);
  return ParseSignalCsv(input, "test.csv", signal, options);
}

TEST(SignalCsv, ReadsHeaderNamesAndChannels) {
  const std::string text =
      "# produced by a test\n"
      "time, x, \"velocity\"\r\n"
      "0.5, 1.0, -2.0\r\n"
      "0.75, 1.5, -2.5\n"
      "\n"
      "1.0, +2.0, -3e0\n"
      "1.25, 2.5, -3.5\n";
  Signal signal;
  const CsvReadResult result = Parse(text, &signal);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_DOUBLE_EQ(signal.t0, 0.5);
  EXPECT_DOUBLE_EQ(signal.dt, 0.25);
  ASSERT_EQ(signal.num_samples(), 4);
  ASSERT_EQ(signal.num_channels(), 2);
  EXPECT_EQ(signal.channel_names, (std::vector<std::string>{"x", "velocity"}));
  EXPECT_DOUBLE_EQ(signal.samples(2, 0), 2.0);
  EXPECT_DOUBLE_EQ(signal.samples(3, 1), -3.5);
}

TEST(SignalCsv, HeaderIsOptional) {
  Signal signal;
  const CsvReadResult result = Parse("0,1\n0.1,2\n0.2,3\n0.3,4\n0.4,5\n", &signal);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_TRUE(signal.channel_names.empty());
  EXPECT_EQ(signal.num_samples(), 5);
  EXPECT_NEAR(signal.dt, 0.1, 1e-15);
}

TEST(SignalCsv, ReadsAFileAndReportsAMissingOne) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / "rmhb_frequency_id_signal_io_test.csv";
  {
    std::ofstream file(path);
    file << "t,a\n";
    for (int n = 0; n < 10; ++n) file << 0.1 * n << "," << n * n << "\n";
  }
  Signal signal;
  CsvReadResult result = ReadSignalCsv(path.string(), &signal);
  ASSERT_TRUE(result.ok()) << result.message;
  EXPECT_EQ(signal.num_samples(), 10);
  EXPECT_DOUBLE_EQ(signal.samples(9, 0), 81.0);
  std::filesystem::remove(path);

  result = ReadSignalCsv(path.string(), &signal);
  EXPECT_EQ(result.status, CsvStatus::kCannotOpen);
  EXPECT_NE(result.message.find(path.string()), std::string::npos);
}

TEST(SignalCsv, NonNumericCellGivesLineAndColumn) {
  Signal signal;
  signal.dt = 42.0;  // untouched on failure
  const CsvReadResult result = Parse("t,x,y\n0,1,2\n1,3,4\n2,5,abc\n3,7,8\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kNonNumeric);
  EXPECT_EQ(result.line, 4);
  EXPECT_EQ(result.column, 3);
  EXPECT_NE(result.message.find("test.csv:4:3"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("'abc'"), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("'y'"), std::string::npos) << result.message;
  EXPECT_EQ(signal.dt, 42.0);
}

TEST(SignalCsv, EmptyAndNonFiniteCellsAreErrors) {
  Signal signal;
  CsvReadResult result = Parse("0,1\n1,\n2,3\n3,4\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kNonNumeric);
  EXPECT_EQ(result.line, 2);
  EXPECT_EQ(result.column, 2);
  result = Parse("0,1\n1,nan\n2,3\n3,4\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kNonNumeric);
  result = Parse("0,1\n1,2\n2,1e999\n3,4\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kNonNumeric);
  EXPECT_EQ(result.line, 3);
}

TEST(SignalCsv, RaggedRow) {
  Signal signal;
  CsvReadResult result = Parse("t,x,y\n0,1,2\n1,3\n2,5,6\n3,7,8\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kRaggedRow);
  EXPECT_EQ(result.line, 3);
  EXPECT_EQ(result.column, 3);  // the first missing field
  EXPECT_NE(result.message.find("2 fields, expected 3"), std::string::npos) << result.message;
  result = Parse("0,1\n1,3\n2,5,6\n3,7\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kRaggedRow);
  EXPECT_EQ(result.line, 3);
  EXPECT_EQ(result.column, 3);  // the first extra field
}

TEST(SignalCsv, NonUniformTimeGivesTheLine) {
  Signal signal;
  CsvReadResult result = Parse("t,x\n0,1\n0.1,2\n0.2,3\n0.35,4\n0.4,5\n0.5,6\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kNonUniformTime);
  EXPECT_EQ(result.line, 5);
  EXPECT_EQ(result.column, 1);
  EXPECT_NE(result.message.find("non-uniform"), std::string::npos) << result.message;

  result = Parse("0,1\n1,2\n1,3\n2,4\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kNonUniformTime);
  EXPECT_EQ(result.line, 3);

  // Times printed with few digits pass with a looser tolerance.
  const std::string rounded = "0,1\n0.333,2\n0.667,3\n1,4\n";
  EXPECT_EQ(Parse(rounded, &signal).status, CsvStatus::kNonUniformTime);
  CsvReadOptions options;
  options.time_tolerance = 1e-2;
  EXPECT_TRUE(Parse(rounded, &signal, options).ok());
  EXPECT_NEAR(signal.dt, 1.0 / 3.0, 1e-15);
}

TEST(SignalCsv, TooFewRowsAndEmptyInput) {
  Signal signal;
  CsvReadResult result = Parse("t,x\n0,1\n1,2\n", &signal);
  EXPECT_EQ(result.status, CsvStatus::kTooFewRows);
  EXPECT_NE(result.message.find("2 data rows"), std::string::npos) << result.message;
  EXPECT_EQ(Parse("", &signal).status, CsvStatus::kEmpty);
  EXPECT_EQ(Parse("# only a comment\nt,x\n", &signal).status, CsvStatus::kEmpty);
  EXPECT_EQ(Parse("0\n1\n2\n3\n", &signal).status, CsvStatus::kNoChannels);
}

TEST(SignalCsv, OtherDelimiter) {
  Signal signal;
  CsvReadOptions options;
  options.delimiter = ';';
  const CsvReadResult result = Parse("t;x\n0;1,5\n", &signal, options);
  // "1,5" (a decimal comma) is not a number here.
  EXPECT_EQ(result.status, CsvStatus::kNonNumeric);
  EXPECT_TRUE(Parse("t;x\n0;1\n1;2\n2;3\n3;4\n", &signal, options).ok());
}

}  // namespace
}  // namespace rmhb::frequency_id
