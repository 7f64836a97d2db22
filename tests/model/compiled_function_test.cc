// The tape compiler behind the fast evaluators (original equations, pinning
// conditions, guesses).

#include <cmath>
#include <stdexcept>

#include <ginac/ginac.h>
#include <gtest/gtest.h>

#include "rmhb/model/internal/compile.h"

namespace rmhb::model {
namespace {

using GiNaC::ex;
using GiNaC::numeric;
using GiNaC::symbol;

TEST(CompiledFunction, MatchesDirectEvaluation) {
  symbol x("x"), y("y");
  const std::vector<ex> outputs{GiNaC::sin(x) * GiNaC::exp(y) + GiNaC::pow(x, 3) / y - GiNaC::sqrt(x),
                                GiNaC::atan(x * y) + GiNaC::tanh(y) - GiNaC::log(1 + x * x),
                                GiNaC::pow(x, y) + GiNaC::cosh(x) * GiNaC::Pi};
  const CompiledFunction f = internal::Compile(outputs, {x, y});
  EXPECT_EQ(f.num_inputs(), 2);
  EXPECT_EQ(f.num_outputs(), 3);
  for (double a : {0.3, 1.7}) {
    for (double b : {-0.8, 2.5}) {
      const std::vector<double> r = f({a, b});
      EXPECT_NEAR(r[0], std::sin(a) * std::exp(b) + a * a * a / b - std::sqrt(a), 1e-14);
      EXPECT_NEAR(r[1], std::atan(a * b) + std::tanh(b) - std::log(1 + a * a), 1e-14);
      EXPECT_NEAR(r[2], std::pow(a, b) + std::cosh(a) * M_PI, 1e-13);
    }
  }
}

TEST(CompiledFunction, SharesSubexpressionsAndFoldsConstants) {
  symbol x("x");
  const ex s = GiNaC::sin(x + 1);
  const CompiledFunction f = internal::Compile({s + GiNaC::pow(s, 2) + GiNaC::log(ex(2))}, {x});
  // x, 1, x+1, sin, sin^2, +, 2, log 2 (folded), +: the sine once.
  EXPECT_LE(f.size(), 9);
  EXPECT_NEAR(f({0.5})[0], std::sin(1.5) + std::pow(std::sin(1.5), 2) + std::log(2.0), 1e-15);
}

TEST(CompiledFunction, RealOddRoots) {
  symbol x("x");
  const CompiledFunction f = internal::Compile(
      {GiNaC::pow(x, numeric(1, 3)), GiNaC::pow(x, numeric(2, 3)), GiNaC::pow(x, numeric(1, 2))}, {x});
  const std::vector<double> r = f({-8.0});
  EXPECT_NEAR(r[0], -2.0, 1e-15);
  EXPECT_NEAR(r[1], 4.0, 1e-14);
  EXPECT_TRUE(std::isnan(r[2]));
  EXPECT_DOUBLE_EQ(internal::EvaluateConstant(GiNaC::pow(ex(-8), numeric(1, 3))), -2.0);
}

TEST(CompiledFunction, NanConstantsStayDistinct) {
  // asin(2) folds to NaN; it must not be mistaken for another constant.
  symbol x("x");
  const CompiledFunction f = internal::Compile({GiNaC::asin(ex(2)) * x, 2 * x}, {x});
  const std::vector<double> r = f({1.0});
  EXPECT_TRUE(std::isnan(r[0]));
  EXPECT_EQ(r[1], 2.0);
  EXPECT_THROW(internal::EvaluateConstant(GiNaC::asin(ex(2))), std::invalid_argument);
}

TEST(CompiledFunction, RefusesUnknownSymbols) {
  symbol x("x"), y("y");
  EXPECT_THROW(internal::Compile({x + y}, {x}), std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::model
