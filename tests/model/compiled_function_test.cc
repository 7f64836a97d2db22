// The tape compiler behind the fast evaluators (original equations, pinning
// conditions, guesses).

#include <cmath>
#include <stdexcept>

#include <Eigen/Dense>
#include <ginac/ginac.h>
#include <gtest/gtest.h>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/nonsmooth.h"

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

// Half-integer powers go through sqrt (no pow): the same values to round-off,
// NaN below zero as pow gives.
TEST(CompiledFunction, HalfIntegerPowers) {
  symbol x("x");
  const CompiledFunction f = internal::Compile(
      {GiNaC::pow(x, numeric(3, 2)), GiNaC::pow(x, numeric(-3, 2)), GiNaC::pow(x, numeric(7, 2))}, {x});
  for (double a : {0.04, 0.7, 3.3}) {
    const std::vector<double> r = f({a});
    EXPECT_NEAR(r[0], std::pow(a, 1.5), 4e-16 * std::pow(a, 1.5));
    EXPECT_NEAR(r[1], std::pow(a, -1.5), 4e-16 * std::pow(a, -1.5));
    EXPECT_NEAR(r[2], std::pow(a, 3.5), 8e-16 * std::pow(a, 3.5));
  }
  EXPECT_TRUE(std::isnan(f({-0.5})[0]));
}

// Many points at once give the bits of one point at a time, for every
// operation the tape has (the switches on their arguments' sides).
TEST(CompiledFunction, ManyPointsMatchOneAtATime) {
  symbol x("x"), y("y");
  const std::vector<ex> outputs{
      GiNaC::sin(x) * GiNaC::exp(y) + GiNaC::pow(x, 3) / y - GiNaC::sqrt(x * x + 1) - x,
      GiNaC::atan(x * y) + GiNaC::tanh(y) - GiNaC::log(1 + x * x) + GiNaC::cos(y) / GiNaC::cosh(x),
      GiNaC::pow(x * x + 1, y) + GiNaC::sinh(x) * GiNaC::Pi + GiNaC::pow(x, numeric(1, 3)) +
          GiNaC::pow(x * x + 2, numeric(5, 2)) + GiNaC::tan(y / 4) + GiNaC::asin(x / 4) + GiNaC::acos(y / 4),
      internal::ramp(x) + internal::heaviside(y) * x + internal::sgn(x - y) * y};
  const CompiledFunction f = internal::Compile(outputs, {x, y});
  const long count = 37;
  Eigen::MatrixXd in(count, 2), out(count, 4);
  for (long t = 0; t < count; ++t) in.row(t) << -2.0 + 0.11 * double(t), 1.5 - 0.09 * double(t);
  std::vector<double> work;
  f.EvaluateMany(count, in.data(), count, out.data(), count, &work);
  for (long t = 0; t < count; ++t) {
    const std::vector<double> one = f({in(t, 0), in(t, 1)});
    for (int i = 0; i < 4; ++i) EXPECT_EQ(out(t, i), one[i]) << "point " << t << ", output " << i;
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
