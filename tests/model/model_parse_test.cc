// Loading model files: the format, and every error reported as a ModelError
// with file:line:column.

#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "rmhb/model/model_definition.h"
#include "rmhb/model/recast.h"

namespace rmhb::model {
namespace {

using ::testing::HasSubstr;

const char* kPendulum = R"yaml(name: pendulum
description: Nonlinear pendulum
variables: [theta]
parameters: {theta0: 1.5}
equations:
  - "theta'' + sin(theta) = 0"
frequencies:
  - {guess: 0.86}
conditions:
  - "theta(0) = theta0"
  - "theta'(0) = 0"
initial_state: {theta: theta0, "theta'": 0}
guess: {theta: "theta0*cos(w*t)"}
)yaml";

// The message of the ModelError that `f` throws ("" if none).
template <class F>
std::string ErrorOf(F f) {
  try {
    f();
  } catch (const ModelError& e) {
    return e.what();
  }
  return "";
}

std::string ParseError(const std::string& text) {
  return ErrorOf([&] { ParseModel(text, "m.yaml"); });
}

std::string RecastError(const std::string& text, const ParameterValues& overrides = {}) {
  return ErrorOf([&] { Recast(ParseModel(text, "m.yaml"), overrides); });
}

// A pendulum with one line replaced.
std::string Pendulum(const std::string& from, const std::string& to) {
  std::string text = kPendulum;
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(ModelParse, ReadsEveryField) {
  const ModelDefinition m = ParseModel(kPendulum, "pendulum.yaml");
  EXPECT_EQ(m.name, "pendulum");
  EXPECT_EQ(m.description, "Nonlinear pendulum");
  EXPECT_EQ(m.source, "pendulum.yaml");
  EXPECT_EQ(m.variables, (std::vector<std::string>{"theta"}));
  EXPECT_EQ(m.orders, (std::vector<int>{2}));
  ASSERT_EQ(m.parameters.size(), 1u);
  EXPECT_EQ(m.parameters[0].name, "theta0");
  EXPECT_DOUBLE_EQ(m.parameters[0].value, 1.5);
  ASSERT_EQ(m.equations.size(), 1u);
  EXPECT_EQ(m.equations[0].text, "theta'' + sin(theta) = 0");
  EXPECT_EQ(m.equations[0].where.line, 6);
  EXPECT_EQ(m.equations[0].where.column, 6);  // after the opening quote
  ASSERT_EQ(m.frequencies.size(), 1u);
  EXPECT_TRUE(m.frequencies[0].unknown);
  EXPECT_EQ(m.frequencies[0].symbol, "w");
  EXPECT_EQ(m.conditions.size(), 2u);
  EXPECT_EQ(m.initial_state.size(), 2u);
  EXPECT_EQ(m.guess.size(), 1u);
}

TEST(ModelParse, NameDefaultsToTheFileName) {
  const ModelDefinition m =
      ParseModel("variables: [x]\nequations: [\"x'' + x = 0\"]\nfrequencies: [1]\n", "dir/osc.yaml");
  EXPECT_EQ(m.name, "osc");
}

TEST(ModelParse, DerivativesOfAnyOrder) {
  const ModelDefinition m = ParseModel(
      "variables: [x, y]\nequations: [\"x'''' + y' = 0\", \"y' + x''' = 0\"]\nfrequencies: [1]\n",
      "m.yaml");
  EXPECT_EQ(m.orders, (std::vector<int>{4, 1}));
}

TEST(ModelParse, FrequencyForms) {
  const ModelDefinition m = ParseModel(
      "variables: [x]\nparameters: {W: 2, a: 0.5}\n"
      "equations: [\"x'' + x = cos(w1*t) + cos(w2*t) + cos(w3*t) + cos(w4*t)\"]\n"
      "frequencies: [W, {guess: 2*a}, 3, {value: \"W + 2\"}]\n",
      "m.yaml");
  ASSERT_EQ(m.num_bases(), 4);
  EXPECT_EQ(m.frequencies[0].parameter, "W");
  EXPECT_EQ(m.frequencies[0].symbol, "W");
  EXPECT_TRUE(m.frequencies[1].unknown);
  EXPECT_EQ(m.frequencies[1].symbol, "w2");
  const RecastResult r = Recast(m, {{"W", 1.5}});
  EXPECT_EQ(r.problem.frequencies, (std::vector<double>{1.5, 1.0, 3.0, 3.5}));
  EXPECT_EQ(r.problem.unknown_frequency, (std::vector<bool>{false, true, false, false}));
}

// A forced model without 'frequencies': the base is read off the forcing,
// a parameter stays one, and the recast is that of the file that names it.
TEST(ModelParse, ForcingFrequencyWhenNoneIsGiven) {
  const std::string equations = "equations: [\"x'' + 0.1*x' + x + x^3 = cos(w*t) + 0.2*sin(3*w*t + 1)\"]\n";
  const ModelDefinition m = ParseModel("variables: [x]\nparameters: {w: 1.5}\n" + equations, "m.yaml");
  ASSERT_EQ(m.num_bases(), 1);
  EXPECT_EQ(m.frequencies[0].parameter, "w");
  EXPECT_FALSE(m.frequencies[0].unknown);
  const RecastResult inferred = Recast(m, {{"w", 1.2}});
  const RecastResult named =
      Recast(ParseModel("variables: [x]\nparameters: {w: 1.5}\n" + equations + "frequencies: [w]\n", "m.yaml"),
             {{"w", 1.2}});
  EXPECT_EQ(inferred.problem.frequencies, (std::vector<double>{1.2}));
  EXPECT_EQ(inferred.problem.frequencies, named.problem.frequencies);
  EXPECT_EQ(inferred.problem.unknown_frequency, named.problem.unknown_frequency);
  // A number, a negative rate, and the smallest of commensurate rates.
  const ModelDefinition number =
      ParseModel("variables: [x]\nequations: [\"x'' + x = cos(-0.8*t) + cos(1.6*t)\"]\n", "m.yaml");
  EXPECT_EQ(Recast(number).problem.frequencies, (std::vector<double>{0.8}));
  const ModelDefinition half = ParseModel(
      "variables: [x]\nparameters: {W: 2}\nequations: [\"x'' + x = sin(W/2*t)*cos(W*t)\"]\n", "m.yaml");
  EXPECT_EQ(Recast(half).problem.frequencies, (std::vector<double>{1.0}));
  // In hertz: the base 2 pi f follows f.
  const ModelDefinition hertz = ParseModel(
      "variables: [x]\nparameters: {f: 0.25}\nequations: [\"x'' + x = cos(2*pi*f*t)\"]\n", "m.yaml");
  EXPECT_NEAR(Recast(hertz, {{"f", 0.5}}).problem.frequencies[0], M_PI, 1e-15);
}

// An autonomous model without 'frequencies' but with initial_state: one
// unknown base, flagged for the loader to read its guess off the trajectory
// (rmhb/pipeline/model.h), then parsed again with that guess.
TEST(ModelParse, AutonomousFrequencyGuessFromTheTrajectory) {
  const std::string text = Pendulum("frequencies:\n  - {guess: 0.86}\n", "");
  const ModelDefinition m = ParseModel(text, "m.yaml");
  EXPECT_TRUE(m.frequency_from_trajectory);
  ASSERT_EQ(m.num_bases(), 1);
  EXPECT_TRUE(m.frequencies[0].unknown);
  EXPECT_EQ(m.frequencies[0].symbol, "w");
  const ModelDefinition guessed = ParseModel(text, "m.yaml", {}, "0.8606");
  EXPECT_FALSE(guessed.frequency_from_trajectory);
  EXPECT_EQ(guessed.frequency_guess, "0.8606");
  const RecastResult r = Recast(guessed);
  EXPECT_EQ(r.problem.frequencies, (std::vector<double>{0.8606}));
  EXPECT_EQ(r.problem.unknown_frequency, (std::vector<bool>{true}));
  // A file that names its frequencies is not touched by the guess.
  EXPECT_EQ(Recast(ParseModel(kPendulum, "m.yaml", {}, "0.5")).problem.frequencies, (std::vector<double>{0.86}));
}

TEST(ModelParse, NaturalNotation) {
  // ** for powers, ln, sqrt, cbrt, log(x, b), arcsin, pi, implicit "= 0".
  const ModelDefinition m = ParseModel(
      "variables: [x]\nequations: [\"x'' + x**3 + ln(1 + x^2) + sqrt(1 + x^2) - 1 + cbrt(x)"
      " + log(2 + x, 3) - log(2, 3) + arcsin(x/2) + pi*x\"]\nfrequencies: [{guess: 1}]\n",
      "m.yaml");
  EXPECT_EQ(m.orders[0], 2);
}

// ---- errors ------------------------------------------------------------------------------
TEST(ModelErrors, UnknownSymbolPointsAtIt) {
  const std::string text = Pendulum("theta'' + sin(theta) = 0", "theta'' + sin(thta) = 0");
  EXPECT_EQ(ParseError(text), "m.yaml:6:20: unknown symbol 'thta' in equation 1");
  try {
    ParseModel(text, "m.yaml");
  } catch (const ModelError& e) {
    EXPECT_EQ(e.file(), "m.yaml");
    EXPECT_EQ(e.line(), 6);
    EXPECT_EQ(e.column(), 20);
    EXPECT_EQ(e.symbol(), "thta");
    EXPECT_EQ(e.message(), "unknown symbol 'thta' in equation 1");
  }
}

TEST(ModelErrors, ColumnsInPlainAndSingleQuotedScalars) {
  EXPECT_EQ(ParseError("variables: [x]\nequations:\n  - x' + y = 0\nfrequencies: [1]\n"),
            "m.yaml:3:10: unknown symbol 'y' in equation 1");
  EXPECT_EQ(ParseError("variables: [x]\nequations: ['x + q = 0']\nfrequencies: [1]\n"),
            "m.yaml:2:18: unknown symbol 'q' in equation 1");
}

TEST(ModelErrors, YamlSyntax) {
  EXPECT_EQ(ParseError("variables: [x\nequations: []\n"),
            "m.yaml:2:10: YAML error: end of sequence flow not found");
  EXPECT_EQ(ParseError("variables: [x]\n  equations: x\n"),
            "m.yaml:2:3: YAML error: end of map not found");
  EXPECT_EQ(ParseError(""), "m.yaml:1:1: empty model: expected a YAML map with variables, "
                            "equations, frequencies");
  EXPECT_EQ(ParseError("- a\n- b\n"),
            "m.yaml:1:1: a model must be a YAML map (keys name, variables, parameters, "
            "equations, frequencies, ...)");
}

TEST(ModelErrors, UnknownKey) {
  EXPECT_EQ(ParseError(Pendulum("equations:", "equaitons:")),
            "m.yaml:5:1: unknown key 'equaitons' (expected name, description, variables, "
            "parameters, equations, frequencies, conditions, initial_state, guess)");
}

TEST(ModelErrors, UnsupportedFunctions) {
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "fabs(theta)")),
            "m.yaml:6:16: function 'fabs' is not supported: piecewise-smooth terms are written with abs, "
            "max, min, sign, heaviside, clamp or coulomb (Coulomb friction) in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "max(theta)")),
            "m.yaml:6:16: max() takes 2 arguments, got 1 in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "floor(theta)")).substr(0, 40),
            "m.yaml:6:16: function 'floor' is not sup");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "erf(theta)")),
            "m.yaml:6:16: unknown function 'erf' in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "theta0(theta)")),
            "m.yaml:6:16: 'theta0' is not a function (write products with *) in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "sin(theta, 2)")),
            "m.yaml:6:16: sin() takes 1 argument, got 2 in equation 1");
}

TEST(ModelErrors, MalformedExpressions) {
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "2theta")),
            "m.yaml:6:17: expected an operator after the number '2' (write products with *) in "
            "equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "sin(theta")),
            "m.yaml:6:19: missing ')' for the '(' here in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "* theta")),
            "m.yaml:6:16: unexpected '*' in equation 1");
  EXPECT_EQ(ParseError(Pendulum("= 0", "= 0 = 1")),
            "m.yaml:6:31: more than one '=' in an equation in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "theta $ 2")),
            "m.yaml:6:22: unexpected character '$' in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "1/0")),
            "m.yaml:6:18: cannot evaluate: division by zero in equation 1");  // at the 0
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "theta^1000")),
            "m.yaml:6:22: exponent 1000 too large (at most 64 in magnitude) in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "1e999*theta")),
            "m.yaml:6:16: number '1e999' is out of range in equation 1");
  EXPECT_EQ(ParseError(Pendulum("sin(theta)", "theta0'")),
            "m.yaml:6:16: 'theta0' is a parameter: it has no derivative in equation 1");
  EXPECT_EQ(ParseError(Pendulum("\"theta'' + sin(theta) = 0\"", "\"\"")),
            "m.yaml:6:6: empty expression in equation 1");
}

TEST(ModelErrors, EquationCountAndUnusedVariables) {
  EXPECT_EQ(ParseError("variables: [x, y]\nequations: [\"x'' + x = 0\"]\nfrequencies: [1]\n"),
            "m.yaml:2:12: 1 equation for 2 variables (x, y): give one equation per variable");
  EXPECT_EQ(ParseError(
                "variables: [x, y]\nequations: [\"x'' + x = 0\", \"x' = 1\"]\nfrequencies: [1]\n"),
            "m.yaml:1:16: variable 'y' appears in no equation");
  EXPECT_EQ(ParseError("variables: [x]\nparameters: {a: 1}\nequations: [\"a = 2\"]\nfrequencies: [1]\n"),
            "m.yaml:3:14: equation 1 involves no variable");
  EXPECT_EQ(ParseError("variables: [x]\nequations: [\"x = x\"]\nfrequencies: [1]\n"),
            "m.yaml:2:14: equation 1 is identically zero");
}

TEST(ModelErrors, Names) {
  EXPECT_EQ(ParseError("variables: [t]\nequations: [\"t' = 0\"]\nfrequencies: [1]\n"),
            "m.yaml:1:13: 't' is reserved and cannot be a variable name");
  EXPECT_EQ(ParseError("variables: [w2]\nequations: [\"w2' = 0\"]\nfrequencies: [1]\n"),
            "m.yaml:1:13: 'w2' is reserved and cannot be a variable name (w, w1, w2, ... are the base "
            "frequencies in guesses and conditions): rename it, e.g. w2_");
  EXPECT_EQ(ParseError("variables: [x, x]\nequations: [\"x' = 0\", \"x' = 1\"]\nfrequencies: [1]\n"),
            "m.yaml:1:16: variable 'x' declared twice");
  EXPECT_EQ(ParseError("variables: [x]\nparameters: {sin: 1}\nequations: [\"x' = 0\"]\nfrequencies: [1]\n"),
            "m.yaml:2:14: 'sin' is reserved and cannot be a parameter name");
  EXPECT_EQ(ParseError("variables: [x]\nparameters: {x: 1}\nequations: [\"x' = 0\"]\nfrequencies: [1]\n"),
            "m.yaml:2:14: 'x' is both a variable and a parameter");
  EXPECT_EQ(ParseError("variables: [2x]\nequations: [\"x' = 0\"]\nfrequencies: [1]\n"),
            "m.yaml:1:13: '2x' is not a valid variable name (letters, digits, _)");
}

TEST(ModelErrors, ParameterValues) {
  EXPECT_EQ(ParseError(Pendulum("{theta0: 1.5}", "{theta0: one}")),
            "m.yaml:4:22: parameter 'theta0' must be a finite number, got 'one'");
  EXPECT_EQ(ParseError(Pendulum("{theta0: 1.5}", "{theta0: .inf}")),
            "m.yaml:4:22: parameter 'theta0' must be a finite number, got '.inf'");
  EXPECT_EQ(ParseError(Pendulum("{theta0: 1.5}", "{theta0: [1]}")),
            "m.yaml:4:22: parameter 'theta0' must be a number");
  EXPECT_EQ(ParseError(Pendulum("{theta0: 1.5}", "{theta0: 1.5, theta0: 2}")),
            "m.yaml:4:27: parameter 'theta0' defined twice");
}

TEST(ModelErrors, Overrides) {
  EXPECT_EQ(RecastError(kPendulum, {{"theta1", 1.0}}),
            "m.yaml: unknown parameter 'theta1' in the overrides (parameters: theta0)");
  EXPECT_EQ(RecastError(kPendulum, {{"theta0", std::nan("")}}),
            "m.yaml: parameter 'theta0' set to a non-finite value");
}

TEST(ModelErrors, Frequencies) {
  EXPECT_EQ(ParseError(Pendulum("{guess: 0.86}", "{guess: -1}")),
            "m.yaml:8:13: a base frequency must be > 0 in frequency 1");
  EXPECT_EQ(ParseError(Pendulum("{guess: 0.86}", "{guess: omega}")),
            "m.yaml:8:13: unknown symbol 'omega' in frequency 1");
  EXPECT_EQ(ParseError(Pendulum("{guess: 0.86}", "{gues: 1}")),
            "m.yaml:8:6: unknown key 'gues' in a frequency entry (expected guess or value)");
  // An autonomous model without initial_state: its frequency's guess is
  // read off the trajectory from its guess's state (or from next to rest),
  // as with initial_state.
  std::string bare = Pendulum("frequencies:\n  - {guess: 0.86}\n", "");
  bare.replace(bare.find("initial_state:"), bare.find("guess:") - bare.find("initial_state:"), "");
  EXPECT_TRUE(ParseModel(bare, "m.yaml").frequency_from_trajectory);
  // Missing and not to be read off a forcing: each says why.
  EXPECT_THAT(ParseError("variables: [x]\nequations: [\"x'' + x = t*cos(t)\"]\n"),
              HasSubstr("not only in sin(a*t + b) or cos(a*t + b)"));
  EXPECT_THAT(ParseError("variables: [x]\nequations: [\"x'' + x = cos(x*t)\"]\n"),
              HasSubstr("not only in sin(a*t + b)"));
  EXPECT_THAT(ParseError("variables: [x]\nequations: [\"x'' + x = cos(t) + cos(sqrt(2)*t)\"]\n"),
              HasSubstr("not integer multiples of the smallest"));
  EXPECT_THAT(ParseError("variables: [x]\nequations: [\"x'' + x = cos(omega*t)\"]\n"),
              HasSubstr("missing 'frequencies'"));
  // With two bases, 'w' is ambiguous.
  EXPECT_EQ(ParseError("variables: [x]\nequations: [\"x'' + x = cos(w*t)\"]\nfrequencies: [1, 2]\n"),
            "m.yaml:2:28: unknown symbol 'w' (with several bases write w1, w2, ...) in equation 1");
  // A frequency must not be overridden to 0.
  EXPECT_EQ(RecastError("variables: [x]\nparameters: {W: 1}\nequations: [\"x'' + x = cos(W*t)\"]\n"
                        "frequencies: [W]\n",
                        {{"W", 0.0}}),
            "m.yaml:4:15: base frequency 1 must be finite and > 0 (got 0.000000)");
}

TEST(ModelErrors, Conditions) {
  EXPECT_EQ(ParseError(Pendulum("theta(0) = theta0", "theta(1) = theta0")),
            "m.yaml:10:6: conditions hold at t = 0: write theta(0) in condition 1");
  EXPECT_EQ(ParseError(Pendulum("theta(0) = theta0", "theta = theta0")),
            "m.yaml:10:6: write theta(0): conditions hold at t = 0 in condition 1");
  EXPECT_EQ(ParseError(Pendulum("theta(0) = theta0", "theta'''(0) = 0")),
            "m.yaml:10:6: theta'''(0) is beyond the highest derivative of theta in the equations "
            "in condition 1");
  EXPECT_EQ(ParseError(Pendulum("theta(0) = theta0", "theta0 = 1")),
            "m.yaml:10:6: condition 1 involves no variable");
  EXPECT_EQ(RecastError(Pendulum("theta(0) = theta0", "theta(0) = w")),
            "m.yaml:10:6: a condition cannot depend on the unknown base frequency 'w' in condition 1");
}

TEST(ModelErrors, InitialStateAndGuess) {
  EXPECT_EQ(ParseError(Pendulum("{theta: theta0, \"theta'\": 0}", "{theta: theta0, \"theta''\": 0}")),
            "m.yaml:12:32: initial_state 'theta''': the state of theta is theta ... theta' (its "
            "equation is of order 2)");
  EXPECT_EQ(ParseError(Pendulum("{theta: theta0, \"theta'\": 0}", "{phi: 0}")),
            "m.yaml:12:17: unknown variable 'phi' in initial_state");
  EXPECT_EQ(RecastError(Pendulum("{theta: theta0, \"theta'\": 0}", "{theta: theta0}")),
            "m.yaml:12:24: initial_state does not give 'theta''");
  EXPECT_EQ(ParseError(Pendulum("theta0*cos(w*t)", "theta*cos(w*t)")),
            "m.yaml:13:17: a guess is a function of t: variables are not allowed in the guess of "
            "theta");
  // A guess outside a definition's domain is reported when the guess is built.
  const RecastResult r = Recast(ParseModel(
      "variables: [x]\nequations: [\"x'' + log(x) = 0\"]\nfrequencies: [{guess: 1}]\n"
      "guess: {x: \"cos(w*t)\"}\n",
      "m.yaml"));
  EXPECT_EQ(ErrorOf([&] { r.InitialGuess(8); }),
            "m.yaml: the initial guess of 'log_x' is not finite (= log(x) on the guessed states)");
}

TEST(ModelErrors, TimeAndFrequencyMisuse) {
  EXPECT_EQ(RecastError(Pendulum("sin(theta)", "t*theta")),
            "m.yaml:6:6: explicit time 't' may only appear in forcing terms cos(k*w*t), "
            "sin(k*w*t) (the response must be periodic) in equation 1");
  EXPECT_EQ(RecastError(Pendulum("sin(theta)", "cos(3*t)")),
            "m.yaml:6:6: cos(3*t) is not a harmonic of the base frequencies: time may only appear "
            "as cos(k*w*t + phase), sin(k*w*t + phase) with integer k in equation 1");
  EXPECT_EQ(RecastError(Pendulum("sin(theta)", "cos(t^2)")),
            "m.yaml:6:6: explicit time 't' may only appear in forcing terms cos(k*w*t), "
            "sin(k*w*t) (the response must be periodic) in equation 1");
  EXPECT_EQ(RecastError(Pendulum("sin(theta)", "w^2*theta")),
            "m.yaml:6:6: the unknown base frequency 'w' appears outside cos/sin(k*w*t); the "
            "solver treats a frequency only through time derivatives and forcing in equation 1");
}

TEST(ModelErrors, ParameterValuesThatBreakAnEquation) {
  const std::string text =
      "variables: [x]\nparameters: {a: 1}\nequations: [\"x'' + x/(a - 1) = 0\"]\nfrequencies: [1]\n";
  EXPECT_EQ(RecastError(text).substr(0, 51), "m.yaml:3:14: cannot substitute the parameter values");
  EXPECT_EQ(RecastError("variables: [x]\nparameters: {a: 1}\nequations: [\"a*x'' = 0\"]\n"
                        "frequencies: [1]\n",
                        {{"a", 0.0}}),
            "m.yaml:3:14: the equation vanishes with these parameter values in equation 1");
}

TEST(ModelErrors, MissingFile) {
  EXPECT_EQ(ErrorOf([] { LoadModelFile("/nonexistent/model.yaml"); }),
            "/nonexistent/model.yaml: cannot open the model file");
}

}  // namespace
}  // namespace rmhb::model
