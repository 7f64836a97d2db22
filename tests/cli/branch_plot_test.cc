// `solve --continue ... --plot`: the frequency response as a picture, read
// back here as a test can read one: the PNG's header, the SVG's labels and
// dashes, and the plotted data against the JSON branch of the same run.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/cli/cli_run.h"

namespace rmhb::testing {
namespace {

namespace fs = std::filesystem;

struct Row {
  double parameter, value;
  std::string stability;
  int fold;
  std::string mark;
  int branch;
};

std::vector<Row> ReadData(const std::string& file) {
  std::ifstream in(file);
  std::vector<Row> rows;
  std::string line;
  std::getline(in, line);  // header
  for (Row r; in >> r.parameter >> r.value >> r.stability >> r.fold >> r.mark >> r.branch;) rows.push_back(r);
  return rows;
}

unsigned BigEndian(const std::string& bytes, size_t at) {
  unsigned v = 0;
  for (size_t i = 0; i < 4; ++i) v = v << 8 | static_cast<unsigned char>(bytes[at + i]);
  return v;
}

std::string Bytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string Temp(const std::string& name) { return (fs::temp_directory_path() / name).string(); }

TEST(BranchPlot, DuffingResponseWithTwoFoldsAndItsStabilityStyles) {
  const std::string png = Temp("rmhb-branch-" + std::to_string(::getpid()) + ".png");
  const nlohmann::json j = Json("solve duffing --set F=0.5 --order 15 --continue w=0.5:3 --plot " + png + " --json");
  ASSERT_EQ(j["plot"], png);
  const std::string bytes = Bytes(png);
  ASSERT_GT(bytes.size(), 24u);
  EXPECT_EQ(bytes.substr(1, 3), "PNG");
  EXPECT_EQ(BigEndian(bytes, 16), 1000u);  // IHDR width
  EXPECT_EQ(BigEndian(bytes, 20), 460u);   // height: one panel
  const std::vector<Row> rows = ReadData(j["plot_data"]);
  const auto& branch = j["branch"];
  ASSERT_EQ(rows.size(), branch.size());
  int folds = 0, stable = 0, unstable = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    EXPECT_NEAR(rows[i].parameter, branch[i]["parameter"].get<double>(), 1e-14);
    EXPECT_NEAR(rows[i].value, branch[i]["amplitude"].get<double>(), 1e-14);
    EXPECT_EQ(rows[i].stability, branch[i]["stability"]);
    EXPECT_EQ(rows[i].fold == 1, branch[i]["fold"].get<bool>());
    folds += rows[i].fold;
    stable += rows[i].stability == "stable";
    unstable += rows[i].stability == "unstable";
  }
  EXPECT_EQ(folds, 2);
  EXPECT_EQ(j["folds"].size(), 2u);
  EXPECT_GT(stable, 10);
  EXPECT_GT(unstable, 3);
  fs::remove(png);
  fs::remove(png + ".dat");
}

TEST(BranchPlot, SvgLabelsTheFoldsAndDashesTheUnstablePart) {
  const std::string svg = Temp("rmhb-branch-" + std::to_string(::getpid()) + ".svg");
  const CliRun run = Cli("solve duffing --set F=0.5 --order 15 --continue w=0.5:3 --quiet --plot " + svg);
  ASSERT_EQ(run.code, 0) << run.out;
  const std::string text = Bytes(svg);
  size_t labels = 0;
  for (size_t at = text.find("fold w = "); at != std::string::npos; at = text.find("fold w = ", at + 1)) ++labels;
  EXPECT_EQ(labels, 2u);
  EXPECT_NE(text.find("stroke-dasharray"), std::string::npos);
  EXPECT_NE(text.find(">unstable<"), std::string::npos);
  fs::remove(svg);
  fs::remove(svg + ".dat");
}

TEST(BranchPlot, FrequencyOfAnAutonomousBranchAndBadRequests) {
  const std::string svg = Temp("rmhb-branch-w-" + std::to_string(::getpid()) + ".svg");
  const nlohmann::json j =
      Json("solve vanderpol --order 20 --continue eps=0.5:1.5 --plot " + svg + " --plot-var frequency --json");
  const std::vector<Row> rows = ReadData(j["plot_data"]);
  ASSERT_EQ(rows.size(), j["branch"].size());
  for (size_t i = 0; i < rows.size(); ++i)
    EXPECT_NEAR(rows[i].value, j["branch"][i]["frequencies"][0].get<double>(), 1e-14);
  fs::remove(svg);
  fs::remove(svg + ".dat");
  const CliRun bad_var = Cli("solve duffing --continue w=1:2 --plot " + svg + " --plot-var y");
  EXPECT_EQ(bad_var.code, 2);
  EXPECT_NE(bad_var.out.find("no variable 'y' (variables: x"), std::string::npos) << bad_var.out;
  const CliRun no_plot = Cli("solve duffing --continue w=1:2 --plot-var x");
  EXPECT_EQ(no_plot.code, 2);
  EXPECT_NE(no_plot.out.find("--plot-var needs --plot"), std::string::npos) << no_plot.out;
  EXPECT_FALSE(fs::exists(svg));
}

}  // namespace
}  // namespace rmhb::testing
