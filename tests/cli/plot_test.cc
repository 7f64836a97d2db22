// --plot: PNG/SVG through gnuplot, and a clean error without it.

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <string>

#include "tests/cli/cli_run.h"

namespace {

using rmhb::testing::Cli;
using rmhb::testing::Capture;

bool HaveGnuplot() { return Capture("command -v gnuplot >/dev/null 2>&1").code == 0; }

long FileSize(const std::string& file) {
  struct stat st;
  return stat(file.c_str(), &st) == 0 ? static_cast<long>(st.st_size) : -1;
}

// PNG files start with these 8 bytes.
bool IsPng(const std::string& file) {
  FILE* f = std::fopen(file.c_str(), "rb");
  if (!f) return false;
  unsigned char sig[8] = {};
  const size_t n = std::fread(sig, 1, 8, f);
  std::fclose(f);
  return n == 8 && sig[0] == 0x89 && sig[1] == 'P' && sig[2] == 'N' && sig[3] == 'G';
}

TEST(Plot, EveryCommandDrawsAPng) {
  if (!HaveGnuplot()) GTEST_SKIP() << "gnuplot not installed";
  const std::string dir = ::testing::TempDir();
  const std::string files[] = {dir + "plot_simulate.png", dir + "plot_convergence.png",
                               dir + "plot_solve.png", dir + "plot_identify.png", dir + "plot_analyze.png"};
  for (const auto& f : files) std::remove(f.c_str());
  EXPECT_EQ(Cli("simulate pendulum --t-end 10 --csv " + dir + "plot.csv --plot " + files[0]).code, 0);
  EXPECT_EQ(Cli("convergence pendulum --orders 5,10 --methods rhb,hdhb --plot " + files[1]).code, 0);
  EXPECT_EQ(Cli("solve pendulum --order 15 --quiet --plot " + files[2]).code, 0);
  EXPECT_EQ(Cli("identify vanderpol --t-end 400 --plot " + files[3]).code, 0);
  EXPECT_EQ(Cli("analyze pendulum --frequencies ?0.86 --plot " + files[4]).code, 0);
  for (const auto& f : files) {
    EXPECT_GT(FileSize(f), 1000) << f;
    EXPECT_TRUE(IsPng(f)) << f;
  }
  const std::string svg = dir + "plot_simulate.svg";
  EXPECT_EQ(Cli("simulate pendulum --t-end 10 --csv " + dir + "plot.csv --plot " + svg).code, 0);
  EXPECT_GT(FileSize(svg), 1000);
}

TEST(Plot, MissingGnuplotIsACleanError) {
  const std::string png = ::testing::TempDir() + "plot_nognuplot.png";
  const auto r = Capture("PATH=/nonexistent " + std::string(RMHB_CLI) + " simulate pendulum --t-end 1 --csv " +
                         ::testing::TempDir() + "plot.csv --plot " + png + " 2>&1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("gnuplot not found: install gnuplot-nox"), std::string::npos) << r.out;
}

TEST(Plot, UnknownFormatIsRefused) {
  const auto r = Cli("simulate pendulum --t-end 1 --csv " + ::testing::TempDir() + "plot.csv --plot x.jpg");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find(".png or .svg"), std::string::npos) << r.out;
}

}  // namespace
