// The paper's Table 1 experiment in small: random starts on the forced
// Duffing oscillator at w = 2 where three periodic solutions coexist. RHB
// (alias-free) finds exactly those three and nothing else; HDHB at the same
// low order also finds non-physical (aliased) ones. The three are checked
// against their own independent references: the one-harmonic amplitude roots
// and the stability verdicts of tests/rmhb/stability_test.cc.

#include <gtest/gtest.h>

#include <cmath>

#include "examples/example_system.h"
#include "rmhb/monte_carlo.h"

namespace rmhb {
namespace {

MonteCarloOptions Options(long starts, int threads) {
  MonteCarloOptions o;
  o.starts = starts;
  o.threads = threads;
  o.seed = 7;
  o.solve.order = 3;
  return o;
}

const examples::ExampleSetup& Duffing() {
  static const examples::ExampleSetup e = examples::BuildExample("duffing", {{"w", 2.0}});
  return e;
}

TEST(MonteCarlo, RhbFindsOnlyTheThreePhysicalSolutionsHdhbAlsoAliasedOnes) {
  const MonteCarloSummary s = RunMonteCarlo(Duffing().problem, Options(200, 2));
  SCOPED_TRACE(s.FullReport());
  ASSERT_EQ(s.rules.size(), 2u);
  const RuleCensus& rhb = s.rules[0];
  const RuleCensus& hdhb = s.rules[1];
  EXPECT_EQ(rhb.rule, SamplingRule::kRhb);
  EXPECT_GE(rhb.samples, rhb.alias_free_samples);
  EXPECT_LT(hdhb.samples, hdhb.alias_free_samples);
  EXPECT_GT(rhb.converged, 150);
  ASSERT_EQ(rhb.clusters.size(), 3u);
  EXPECT_EQ(rhb.non_physical_clusters(), 0);
  // Upper and lower stable, the middle one the saddle; amplitudes near the
  // one-harmonic roots A = 0.33, 1.84, 2.15 of ((A^2 3/4 - 3)^2 + 0.04) A^2 = 1.
  std::vector<std::pair<double, SolutionClass>> found;
  for (const auto& c : rhb.clusters) found.push_back({c.amplitude, c.solution_class});
  std::sort(found.begin(), found.end());
  EXPECT_NEAR(found[0].first, 0.33, 0.03);
  EXPECT_NEAR(found[1].first, 1.84, 0.1);
  EXPECT_NEAR(found[2].first, 2.15, 0.1);
  EXPECT_EQ(found[0].second, SolutionClass::kPhysicalStable);
  EXPECT_EQ(found[1].second, SolutionClass::kPhysicalUnstable);
  EXPECT_EQ(found[2].second, SolutionClass::kPhysicalStable);
  double total = 0;
  for (const auto& c : rhb.clusters) {
    total += c.share;
    EXPECT_LT(c.reference_distance, 0.01);  // truncation at N = 3, far below the tolerance
  }
  EXPECT_NEAR(total, 100, 1e-9);
  EXPECT_GT(hdhb.non_physical_clusters(), 0);
  EXPECT_GT(hdhb.share(SolutionClass::kNonPhysical), 5.0);
  // HDHB's physical solutions are the same three.
  for (const auto& c : hdhb.clusters)
    if (c.solution_class != SolutionClass::kNonPhysical) {
      double nearest = HUGE_VAL;
      for (const auto& f : found) nearest = std::min(nearest, std::abs(f.first - c.amplitude));
      EXPECT_LT(nearest, 0.05) << c.amplitude;
    }
}

TEST(MonteCarlo, SameSeedSameCensusWhateverTheThreadCount) {
  const MonteCarloSummary one = RunMonteCarlo(Duffing().problem, Options(40, 1));
  const MonteCarloSummary three = RunMonteCarlo(Duffing().problem, Options(40, 3));
  for (size_t r = 0; r < one.rules.size(); ++r) {
    ASSERT_EQ(one.rules[r].clusters.size(), three.rules[r].clusters.size());
    EXPECT_EQ(one.rules[r].converged, three.rules[r].converged);
    for (size_t c = 0; c < one.rules[r].clusters.size(); ++c) {
      EXPECT_EQ(one.rules[r].clusters[c].count, three.rules[r].clusters[c].count);
      EXPECT_EQ(one.rules[r].clusters[c].representative.coefficients(),
                three.rules[r].clusters[c].representative.coefficients());
    }
  }
  // Another seed draws other starts.
  EXPECT_NE(RandomStart(7, 3, 2, 7, -2, 2), RandomStart(8, 3, 2, 7, -2, 2));
  EXPECT_EQ(RandomStart(7, 3, 2, 7, -2, 2), RandomStart(7, 3, 2, 7, -2, 2));
  const Eigen::MatrixXd x = RandomStart(7, 3, 2, 1000, -2, 2);
  EXPECT_GE(x.minCoeff(), -2);
  EXPECT_LT(x.maxCoeff(), 2);
  EXPECT_NEAR(x.mean(), 0, 0.15);  // uniform: mean 0, standard error 0.026
}

TEST(MonteCarlo, RefusesBadOptions) {
  MonteCarloOptions o = Options(0, 1);
  EXPECT_THROW(RunMonteCarlo(Duffing().problem, o), std::invalid_argument);
  o = Options(10, 1);
  o.low = 2;
  o.high = -2;
  EXPECT_THROW(RunMonteCarlo(Duffing().problem, o), std::invalid_argument);
  o = Options(10, 1);
  EXPECT_THROW(RunMonteCarlo(examples::BuildExample("pendulum").problem, o), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb
