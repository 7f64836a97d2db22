#include "rmhb/sweep/journal.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace rmhb::sweep {
namespace {

namespace fs = std::filesystem;

std::string TempDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("rmhb-journal-test-" + name + "-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  return dir.string();
}

PointResult SomePoint(long index) {
  const HarmonicBasis basis = HarmonicBasis::Periodic(3);
  Eigen::MatrixXd c(1, basis.num_coefficients());
  for (int k = 0; k < c.cols(); ++k) c(0, k) = std::sqrt(2.0 + k + index) / 3;  // not short in decimal
  PointResult p;
  p.index = index;
  p.values = {0.1 * index, 1.0 / 3};
  p.status = PointStatus::kSolved;
  p.solves = 9;
  p.solutions.push_back({HarmonicSolution(basis, {M_PI / 3}, c, {Variable{"x", VariableRole::kState, ""}}), 1.25, 3e-16, "start 2",
                         "unstable", 0.0123456789012345678});
  return p;
}

TEST(Journal, PointsReadBackToTheSameBits) {
  const PointResult p = SomePoint(5);
  const PointResult q = PointFromJson(nlohmann::json::parse(PointToJson(p).dump()), HarmonicBasis::Periodic(3),
                                      {Variable{"x", VariableRole::kState, ""}});
  EXPECT_EQ(q.values, p.values);
  EXPECT_EQ(q.solutions[0].solution.frequencies(), p.solutions[0].solution.frequencies());
  EXPECT_EQ(q.solutions[0].solution.coefficients(), p.solutions[0].solution.coefficients());
  EXPECT_EQ(q.solutions[0].max_real_part, p.solutions[0].max_real_part);
  EXPECT_EQ(q.solutions[0].route, "start 2");
  EXPECT_EQ(q.status, PointStatus::kSolved);
}

TEST(Journal, TornLinesAreSkippedDuplicatesCountedOtherSweepsRefused) {
  const std::string dir = TempDir("torn");
  {
    JournalWriter a(dir, 1, "sweep-A");
    a.Append(PointToJson(SomePoint(0)));
    a.Append(PointToJson(SomePoint(1)));
    JournalWriter b(dir, 2, "sweep-A");
    b.Append(PointToJson(SomePoint(1)));  // computed twice
    // A kill in the middle of a line: no newline, cut JSON.
    std::ofstream(b.path(), std::ios::app) << PointToJson(SomePoint(2)).dump().substr(0, 40);
  }
  const JournalContents contents = ReadJournals(dir, "sweep-A");
  EXPECT_EQ(contents.files, 2);
  EXPECT_EQ(contents.points.size(), 2u);
  EXPECT_EQ(contents.duplicates, 1);
  EXPECT_EQ(contents.torn_lines, 1);
  EXPECT_THROW(ReadJournals(dir, "sweep-B"), std::invalid_argument);
  EXPECT_TRUE(ReadJournals(dir + "-missing", "sweep-A").points.empty());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rmhb::sweep
