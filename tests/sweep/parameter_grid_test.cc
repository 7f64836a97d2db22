#include "rmhb/sweep/parameter_grid.h"

#include <gtest/gtest.h>

namespace rmhb::sweep {
namespace {

TEST(ParameterGrid, ParsesAxesAndEnumeratesFirstAxisFastest) {
  const ParameterGrid grid({ParseGridAxis("w=0.5:2.5:5"), ParseGridAxis("F=1:2:3")});
  EXPECT_EQ(grid.size(), 15);
  EXPECT_EQ(grid.num_lines(), 3);
  EXPECT_EQ(grid.line_length(), 5);
  EXPECT_EQ(grid.Indices(7), (std::vector<int>{2, 1}));
  EXPECT_EQ(grid.Values(7), (std::vector<double>{1.5, 1.5}));
  EXPECT_EQ(grid.Values(14), (std::vector<double>{2.5, 2}));  // both ends exact
  EXPECT_EQ(grid.LineOf(7), 1);
  EXPECT_EQ(grid.FirstPointOf(2), 10);
  EXPECT_EQ(ParseGridAxis("a=3:7:1").Value(0), 3);
}

TEST(ParameterGrid, BadAxesSayWhatIsWrong) {
  for (const char* bad : {"w", "=1:2:3", "w=1:2", "w=1:2:3:4", "w=a:2:3", "w=1:2:0", "w=1:2:2.5", "w=1:1:3",
                          "w=1:inf:3", "w=1:2:-1"}) {
    try {
      ParseGridAxis(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(bad[0] == '=' ? "NAME" : "w"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(ParameterGrid({}), std::invalid_argument);
  EXPECT_THROW(ParameterGrid({ParseGridAxis("w=1:2:3"), ParseGridAxis("w=3:4:2")}), std::invalid_argument);
  EXPECT_THROW(ParameterGrid({ParseGridAxis("w=1:2:100000"), ParseGridAxis("F=1:2:100000")}, 1'000'000),
               std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::sweep
