// White-box: the natural-notation reader on top of GiNaC::parser. The
// expected expressions are built with GiNaC's C++ operators, independently of
// any parser; the hostile inputs are the ones GiNaC's parser alone mishandles
// (misreads, crashes or hangs on).

#include <chrono>
#include <string>

#include <ginac/ginac.h>
#include <gtest/gtest.h>

#include "rmhb/model/internal/expression_parser.h"

namespace rmhb::model::internal {
namespace {

using GiNaC::ex;
using GiNaC::numeric;

class ExpressionParserTest : public ::testing::Test {
 protected:
  ExpressionParserTest() {
    resolver_.symbol = [this](const std::string& name, int primes, std::size_t offset) -> ex {
      if (name == "x" && primes <= 2) return dx_[primes];
      if (primes == 0 && name == "y") return y_;
      if (primes == 0 && name == "I") return i_;  // GiNaC's literal for sqrt(-1)
      if (primes == 0 && name == "Pi") return pi_;
      throw ParseError{offset, "unknown symbol '" + name + "'", name};
    };
  }
  ex Read(const std::string& text) { return ParseExpression(text, resolver_); }
  ex ReadEquation(const std::string& text) { return ParseEquation(text, resolver_); }
  // "offset: message" of the ParseError, "" if none.
  std::string Error(const std::string& text, bool equation = false) {
    try {
      equation ? ReadEquation(text) : Read(text);
    } catch (const ParseError& e) {
      return std::to_string(e.offset) + ": " + e.message;
    }
    return "";
  }
  static bool Same(const ex& a, const ex& b) { return (a - b).expand().is_zero(); }

  GiNaC::symbol dx_[3] = {GiNaC::symbol("x"), GiNaC::symbol("x'"), GiNaC::symbol("x''")};
  GiNaC::symbol y_{"y"}, i_{"I"}, pi_{"Pi"};
  const GiNaC::symbol& x_ = dx_[0];
  Resolver resolver_;
};

TEST_F(ExpressionParserTest, PrecedenceAndSignsAsWritten) {
  // GiNaC's parser alone reads these three as 2^(-1+x), -(y-1)*x and an error.
  EXPECT_TRUE(Same(Read("2^-1 + x"), numeric(1, 2) + x_));
  EXPECT_TRUE(Same(Read("x*-y + 1"), -x_ * y_ + 1));
  EXPECT_TRUE(Same(Read("x^y^2"), GiNaC::pow(x_, GiNaC::pow(y_, 2))));
  EXPECT_TRUE(Same(Read("x - -y + 1"), x_ + y_ + 1));
  EXPECT_TRUE(Same(Read("-x^2 + y"), -GiNaC::pow(x_, 2) + y_));
  EXPECT_TRUE(Same(Read("2^-x^2"), GiNaC::pow(2, -GiNaC::pow(x_, 2))));
  EXPECT_TRUE(Same(Read("x**3 / y / 2"), GiNaC::pow(x_, 3) / y_ / 2));
  EXPECT_TRUE(Same(Read("- - x"), x_));
  EXPECT_TRUE(Same(ReadEquation("x'' + x = -y"), dx_[2] + x_ + y_));
}

TEST_F(ExpressionParserTest, ExactDecimalsPrimesAndFunctions) {
  EXPECT_TRUE(Read("x^1.5").is_equal(GiNaC::pow(x_, numeric(3, 2))));
  EXPECT_TRUE(Read("0.85").is_equal(numeric(17, 20)));
  EXPECT_TRUE(Read("1.5e-3").is_equal(numeric(3, 2000)));
  EXPECT_TRUE(Same(Read("x'' + 2*x'"), dx_[2] + 2 * dx_[1]));
  EXPECT_TRUE(Same(Read("log(x, 2) + ln(y) + sqrt(x) + cbrt(y) + pow(x, 3) + arcsin(x)"),
                   GiNaC::log(x_) / GiNaC::log(ex(2)) + GiNaC::log(y_) + GiNaC::sqrt(x_) +
                       GiNaC::pow(y_, numeric(1, 3)) + GiNaC::pow(x_, 3) + GiNaC::asin(x_)));
  // Names GiNaC's lexer would take for its literals stay the model's names.
  EXPECT_TRUE(Same(Read("I*Pi"), i_ * pi_));
}

TEST_F(ExpressionParserTest, ErrorsNameThePlace) {
  EXPECT_EQ(Error("sin()"), "0: sin() needs an argument");  // GiNaC alone: a crash
  EXPECT_EQ(Error("x + sin(x, y)"), "4: sin() takes 1 argument, got 2");
  EXPECT_EQ(Error("x + erf(x)"), "4: unknown function 'erf'");
  EXPECT_EQ(Error("x + z"), "4: unknown symbol 'z'");
  EXPECT_EQ(Error("(x + y"), "0: missing ')' for the '(' here");
  EXPECT_EQ(Error("x + y)"), "5: unbalanced ')'");
  EXPECT_EQ(Error("x y"), "2: expected an operator before 'y' (write products with *)");
  EXPECT_EQ(Error("x +"), "3: unexpected end of expression");
  EXPECT_EQ(Error("x = y"), "2: '=' is not allowed here");
  EXPECT_EQ(Error("x = y = 1", true), "6: more than one '=' in an equation");
  // y - y is 0 already inside GiNaC's parser: then the start is named.
  EXPECT_EQ(Error("x + log(y - y)"), "0: cannot evaluate: log_eval(): log(0)");
  EXPECT_EQ(Error("x + log(0)"), "8: cannot evaluate: log_eval(): log(0)");
  EXPECT_EQ(Error("x + sqrt(-4)"), "10: complex value 2*I");
  EXPECT_EQ(Error("x + 1/(2 - 2)"), "7: cannot evaluate: division by zero");
}

TEST_F(ExpressionParserTest, HostileInputIsBoundedBeforeGinac) {
  const auto start = std::chrono::steady_clock::now();
  // Exact arithmetic would never finish 10^(10^10).
  EXPECT_EQ(Error("10^10^10"), "3: exponent 10000000000 too large (at most 64 in magnitude)");
  EXPECT_EQ(Error("x^(2*500)"), "3: exponent 1000 too large (at most 64 in magnitude)");
  EXPECT_EQ(Error("1e300^64"), "0: number out of range (beyond 1e308)");
  const std::string digits = Error("((((2/3)^64)^64)^64)^64");
  EXPECT_EQ(digits.substr(0, 10), "4: number ");
  EXPECT_NE(digits.find("has too many digits"), std::string::npos) << digits;
  EXPECT_EQ(Error(std::string(300, '(') + "x" + std::string(300, ')')),
            "200: expression nested too deeply");
  std::string signs;
  for (int i = 0; i < 300; ++i) signs += "- ";
  EXPECT_EQ(Error(signs + "x"), "402: expression nested too deeply");
  std::string chain = "x";
  for (int i = 0; i < 300; ++i) chain += "^x";
  EXPECT_EQ(Error(chain), "402: expression nested too deeply");
  std::string sum = "x";
  for (int i = 0; i < 3000; ++i) sum += " + x*y";
  EXPECT_TRUE(Same(Read(sum), x_ + 3000 * x_ * y_));
  EXPECT_EQ(Error(std::string(20001, 'x')).substr(0, 24), "0: expression too long (");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

}  // namespace
}  // namespace rmhb::model::internal
