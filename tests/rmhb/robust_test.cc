// Requests too large for memory are refused before anything is allocated
// (HarmonicBalanceOptions::max_jacobian_bytes), and order selection stops at
// the largest order that fits. The count it refuses by is checked against
// the residual that would be built.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "examples/example_system.h"
#include "rmhb/harmonic_balance.h"

namespace rmhb {
namespace {

// The estimate is the uncondensed residual's own size: checked on every
// basis shape it has a formula for.
TEST(JacobianSize, MatchesTheResidualItSizes) {
  for (const char* name : {"duffing", "pendulum", "forced-vanderpol", "duffing-2tone"}) {
    const examples::ExampleSetup e = examples::BuildExample(name);
    for (BasisShape shape : {BasisShape::kDiamond, BasisShape::kBox})
      for (int order : {1, 3, 7}) {
        HarmonicBalanceOptions o;
        o.order = order;
        o.shape = shape;
        const int d = static_cast<int>(e.problem.frequencies.size());
        const HarmonicBasis basis = MakeBasis(d, o);
        std::vector<int> samples;
        for (int b = 0; b < d; ++b) samples.push_back(4 * order + 8);
        CollocationResidual r(e.problem, basis, d == 1 ? Sampling::Uniform(samples[0]) : Sampling::Torus(samples));
        const JacobianSize size = DenseJacobianSize(e.problem, o);
        EXPECT_EQ(size.columns, r.num_full_unknowns()) << name << " order " << order;
        EXPECT_EQ(size.rows, r.num_full_residuals()) << name << " order " << order;
      }
  }
}

TEST(JacobianSize, RefusesAnOrderTooLargeBeforeAllocating) {
  const examples::ExampleSetup e = examples::BuildExample("duffing");
  HarmonicBalanceOptions o;
  o.order = 1000000;
  const auto start = std::chrono::steady_clock::now();
  try {
    SolveHarmonicBalance(e.problem, e.guess, o);
    FAIL() << "order 1e6 was not refused";
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    // 2 variables x 2000001 coefficients: 4000002 columns and rows.
    EXPECT_NE(what.find("order 1000000 needs a dense Jacobian of 4000002 x 4000002 doubles"),
              std::string::npos) << what;
    EXPECT_NE(what.find("the limit is 4 GiB"), std::string::npos) << what;
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 0.5);
  // Quasi-periodic: p = 1e5 on the diamond is 2e10 coefficients per
  // variable, never built.
  const examples::ExampleSetup q = examples::BuildExample("duffing-2tone");
  o.order = 100000;
  EXPECT_THROW(CheckJacobianSize(q.problem, o), std::invalid_argument);
  o.order = 10;
  EXPECT_NO_THROW(CheckJacobianSize(q.problem, o));
  o.max_jacobian_bytes = DenseJacobianSize(q.problem, o).bytes() - 1;
  EXPECT_THROW(CheckJacobianSize(q.problem, o), std::invalid_argument);
}

// The relativistic oscillator needs order ~45 for 1e-12; with room for
// order 30 only, order selection stops there and says why.
TEST(JacobianSize, OrderSelectionStopsAtTheBound) {
  const examples::ExampleSetup e = examples::BuildExample("relativistic");
  HarmonicBalanceOptions o;
  o.order = 12;
  o.tolerance = 1e-13;
  o.order = 30;
  o.max_jacobian_bytes = DenseJacobianSize(e.problem, o).bytes();
  o.order = 12;
  const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
  EXPECT_EQ(s.solver.status, SolverStatus::kNoConvergence);
  EXPECT_LE(s.order, 30);
  EXPECT_EQ(s.orders_tried.back(), 30);
  EXPECT_NE(s.solver.message.find("not reached by order 30, the largest whose dense Jacobian fits"),
            std::string::npos) << s.solver.message;
  EXPECT_GT(s.truncation_estimate, 1e-13);
}

}  // namespace
}  // namespace rmhb
