// Model files as a user writes them (not bundled, not tuned): an autonomous
// oscillation with its frequency unknown and nothing else but the equation,
// a frequency guess and initial_state. The defaults must supply the start
// (the harmonic through initial_state), the conditions (the orbit through
// initial_state when the trajectory returns to it, else the phase only) and
// refuse a frequency that is a sub-multiple of the orbit's. Each answer is
// checked against an independent reference: a closed form, or the period
// CVODE measures between zero crossings.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "examples/references.h"
#include "integrators/event_detection.h"
#include "rmhb/pipeline/model.h"
#include "tests/cli/cli_run.h"

namespace rmhb::testing {
namespace {

using examples::EllipticK;
using examples::PendulumFrequency;
using examples::RelativisticPeriod;

std::string WriteModel(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/defaults_" + name + ".yaml";
  std::ofstream(path) << text;
  return path;
}

double Frequency(const nlohmann::json& j) { return j["frequencies"][0].get<double>(); }

// The limit cycle's period from the file's initial_state: CVODE at rtol
// 1e-13, the mean spacing of the first variable's upward crossings of
// `level` over [0, t_end] after `transient` of them.
double CvodePeriod(const std::string& model_path, double t_end, int transient, double level = 0) {
  const Model model = LoadModel(model_path);
  integrators::IntegratorOptions tight;
  tight.relative_tolerance = 1e-13;
  tight.absolute_tolerance = 1e-15;
  return integrators::LimitCyclePeriod(model.original(model.problem.frequencies), model.initial_state, t_end,
                                       [level](double, const double* y) { return y[0] - level; }, +1, transient,
                                       tight);
}

// A hardening Duffing oscillator released at rest from A = 1: its orbits form
// a family, the default conditions pick the one through initial_state, and
// the default start is 1*cos(w t), no identification needed. Exact:
// w = pi sqrt(1 + A^2) / (2 K(m)), m = A^2 / (2 (1 + A^2)).
TEST(Defaults, ConservativeOrbitThroughTheInitialState) {
  const std::string model = WriteModel("duffing", "variables: [x]\nequations: [\"x'' + x + x^3 = 0\"]\n"
                                                  "frequencies: [{guess: 1}]\ninitial_state: {x: 1, \"x'\": 0}\n");
  const auto j = Json("solve " + model + " --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  const double exact = M_PI * std::sqrt(2.0) / (2 * EllipticK(0.25));
  EXPECT_NEAR(Frequency(j), exact, 1e-12 * exact);
  EXPECT_EQ(j["start"], "guess");
  const auto& d = j["default_conditions"];
  ASSERT_EQ(d["conditions"].size(), 2u) << j.dump();
  EXPECT_EQ(d["conditions"][0], "x(0) = (1)");
  EXPECT_EQ(d["conditions"][1], "x'(0) = (0)");
  EXPECT_NE(d["note"].get<std::string>().find("the orbit through initial_state"), std::string::npos);
  std::remove(model.c_str());
}

// Kepler's problem in the plane, from perihelion-free data (r = 1, speed
// 1.2 tangential): four states, four default conditions (the orbit through
// them), a radical recast. Exact: T = 2 pi a^(3/2), a = -1 / (2 E),
// E = v^2 / 2 - 1 / r.
TEST(Defaults, KeplerOrbitOfAUsersFile) {
  const std::string model = WriteModel("kepler", "variables: [x, y]\nequations:\n"
                                                 "  - \"x'' = -x/(x^2 + y^2)^(3/2)\"\n"
                                                 "  - \"y'' = -y/(x^2 + y^2)^(3/2)\"\n"
                                                 "frequencies: [{guess: 1}]\n"
                                                 "initial_state: {x: 1, \"x'\": 0, y: 0, \"y'\": 1.2}\n");
  const auto j = Json("solve " + model + " --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  EXPECT_EQ(j["default_conditions"]["conditions"].size(), 4u);
  const double a = -1 / (2 * (0.5 * 1.2 * 1.2 - 1));
  const double exact = 1 / std::pow(a, 1.5);  // 2 pi / T
  EXPECT_NEAR(Frequency(j), exact, 1e-11 * exact);
  std::remove(model.c_str());
}

// Released from x = 0 at speed beta (not at a turning point): the conditions
// are initial_state's own expressions, so they follow a parameter change;
// against the relativistic oscillator's energy quadrature at two betas.
TEST(Defaults, ConservativeOrbitFollowsTheParameters) {
  const std::string model =
      WriteModel("relativistic", "variables: [x]\nparameters: {beta: 0.85}\n"
                                 "equations: [\"x'' + (1 - x'^2)^(3/2)*x = 0\"]\n"
                                 "frequencies: [{guess: 0.77}]\ninitial_state: {x: 0, \"x'\": beta}\n");
  for (const double beta : {0.85, 0.6}) {
    const auto j = Json("solve " + model + " --set beta=" + std::to_string(beta) + " --json");
    ASSERT_EQ(j["status"], "converged") << j.dump();
    EXPECT_EQ(j["default_conditions"]["conditions"][1], "x'(0) = (beta)");
    const double exact = 2 * M_PI / RelativisticPeriod(beta);
    EXPECT_NEAR(Frequency(j), exact, 1e-11 * exact) << beta;
  }
  std::remove(model.c_str());
}

// Rayleigh's oscillator from near the origin: the trajectory does not return
// to initial_state (it spirals out to the limit cycle), so only the phase
// x'(0) = 0 is fixed. The period against CVODE's between upward crossings
// of x after 20 transient ones.
TEST(Defaults, LimitCycleGetsThePhaseOnly) {
  const std::string model = WriteModel("rayleigh", "variables: [x]\nequations: [\"x'' - (1 - x'^2)*x' + x = 0\"]\n"
                                                   "frequencies: [{guess: 1}]\ninitial_state: {x: 0.1, \"x'\": 0}\n");
  const auto j = Json("solve " + model + " --validate --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  const auto& d = j["default_conditions"];
  ASSERT_EQ(d["conditions"].size(), 1u) << j.dump();
  EXPECT_EQ(d["conditions"][0], "x'(0) = 0");
  EXPECT_NE(d["note"].get<std::string>().find("phase only"), std::string::npos);

  const double period = CvodePeriod(model, 400, 20);
  EXPECT_NEAR(2 * M_PI / Frequency(j), period, 1e-9 * period);
  std::remove(model.c_str());
}

// Van der Pol at mu = 5 written by a user: from the cosine through
// initial_state Newton does not reach the relaxation cycle at order 25; the
// identified start seeds it from one exact period of the settled orbit at
// the order its harmonics need (rmhb/METHOD.md s.20). The same frequency as
// the built-in example's (simulated guess, order 40 eps) and as CVODE's
// period between upward crossings.
TEST(Defaults, RelaxationOscillationFromAUsersFile) {
  const std::string model = WriteModel("vdp5", "variables: [x]\nparameters: {mu: 5}\n"
                                               "equations: [\"x'' - mu*(1 - x^2)*x' + x = 0\"]\n"
                                               "frequencies: [{guess: 0.5}]\ninitial_state: {x: 2, \"x'\": 0}\n");
  const auto j = Json("solve " + model + " --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  EXPECT_EQ(j["start"], "identification");
  EXPECT_LT(j["order_selection"]["estimate"].get<double>(), 1e-10);
  const auto builtin = Json("solve vanderpol --set eps=5 --json");
  EXPECT_NEAR(Frequency(j), Frequency(builtin), 1e-13);
  // Without 'frequencies': the guess is the trajectory's exact period, from
  // which the identification of this cycle's lines stops early; the seed
  // from one exact period does not need it.
  const std::string bare = WriteModel("vdp5_bare", "variables: [x]\nparameters: {mu: 5}\n"
                                                   "equations: [\"x'' - mu*(1 - x^2)*x' + x = 0\"]\n"
                                                   "initial_state: {x: 2, \"x'\": 0}\n");
  const auto b = Json("solve " + bare + " --json");
  ASSERT_EQ(b["status"], "converged") << b.dump();
  EXPECT_NEAR(Frequency(b), Frequency(builtin), 1e-13);
  std::remove(bare.c_str());

  const double period = CvodePeriod(model, 600, 10);
  EXPECT_NEAR(2 * M_PI / Frequency(j), period, 1e-9 * period);
  std::remove(model.c_str());
}

// FitzHugh-Nagumo as a user writes it: two first-order equations, no guess
// (first-order variables get none: the zero start finds the rest point, and
// the identified start takes over), no conditions (the trajectory from
// initial_state does not return to it: the phase v'(0) = 0). A slow-fast
// cycle of period ~39 that needs order ~170 for 1e-10. Against CVODE's period
// between upward crossings of v = 0.3.
TEST(Defaults, FirstOrderSystemWithNothingButInitialState) {
  const std::string model = WriteModel("fhn", "variables: [v, r]\nparameters: {a: 0.7, b: 0.8, eps: 0.08, I: 0.5}\n"
                                              "equations:\n  - \"v' = v - v^3/3 - r + I\"\n"
                                              "  - \"r' = eps*(v + a - b*r)\"\n"
                                              "frequencies: [{guess: 0.2}]\ninitial_state: {v: 1, r: 0}\n");
  const auto j = Json("solve " + model + " --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  EXPECT_EQ(j["start"], "identification");
  ASSERT_EQ(j["default_conditions"]["conditions"].size(), 1u) << j.dump();
  EXPECT_EQ(j["default_conditions"]["conditions"][0], "v'(0) = 0");
  EXPECT_LT(j["order_selection"]["estimate"].get<double>(), 1e-10);

  // 0.3 lies inside the cycle's range of v (about -1.9 to 1.9).
  const double period = CvodePeriod(model, 1200, 10, 0.3);
  EXPECT_NEAR(2 * M_PI / Frequency(j), period, 1e-9 * period);
  std::remove(model.c_str());
}

// The same files without 'frequencies' (rmhb/METHOD.md s.20): the guess is
// read off the trajectory from initial_state, between its returns to the
// section through it, and the answer is the hand-guessed file's: a
// conservative family (exact), Kepler (exact), a limit cycle from near the
// origin, a first-order slow-fast cycle.
TEST(Defaults, AnAutonomousFileNeedsNoFrequencies) {
  struct Case {
    std::string name, before, guess, after;
  };
  const std::vector<Case> cases = {
      {"duffing", "variables: [x]\nequations: [\"x'' + x + x^3 = 0\"]\n", "frequencies: [{guess: 1}]\n",
       "initial_state: {x: 1, \"x'\": 0}\n"},
      {"kepler",
       "variables: [x, y]\nequations:\n  - \"x'' = -x/(x^2 + y^2)^(3/2)\"\n"
       "  - \"y'' = -y/(x^2 + y^2)^(3/2)\"\n",
       "frequencies: [{guess: 1}]\n", "initial_state: {x: 1, \"x'\": 0, y: 0, \"y'\": 1.2}\n"},
      {"rayleigh", "variables: [x]\nequations: [\"x'' - (1 - x'^2)*x' + x = 0\"]\n", "frequencies: [{guess: 1}]\n",
       "initial_state: {x: 0.1, \"x'\": 0}\n"},
      {"fhn", "variables: [v, r]\nparameters: {a: 0.7, b: 0.8, eps: 0.08, I: 0.5}\nequations:\n"
              "  - \"v' = v - v^3/3 - r + I\"\n  - \"r' = eps*(v + a - b*r)\"\n",
       "frequencies: [{guess: 0.2}]\n", "initial_state: {v: 1, r: 0}\n"}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string bare = WriteModel(c.name + "_bare", c.before + c.after);
    const std::string named = WriteModel(c.name + "_named", c.before + c.guess + c.after);
    const auto a = Json("solve " + bare + " --json");
    const auto b = Json("solve " + named + " --json");
    ASSERT_EQ(a["status"], "converged") << a.dump();
    ASSERT_EQ(b["status"], "converged") << b.dump();
    EXPECT_NEAR(Frequency(a), Frequency(b), 1e-11 * Frequency(b));
    EXPECT_NE(a["frequency_note"].get<std::string>().find("default guess w = "), std::string::npos);
    EXPECT_FALSE(b.contains("frequency_note"));
    for (const std::string& f : {bare, named}) std::remove(f.c_str());
  }
  const auto duffing = Json("solve " + WriteModel("duffing_bare", cases[0].before + cases[0].after) + " --json");
  const double exact = M_PI * std::sqrt(2.0) / (2 * EllipticK(0.25));
  EXPECT_NEAR(Frequency(duffing), exact, 1e-12 * exact);
}

// Other parameters, another trajectory: the guess is read again (a
// pendulum's frequency falls with its amplitude), and the answer is exact.
TEST(Defaults, TheTrajectoryGuessFollowsTheParameters) {
  const std::string model = WriteModel("pend_amplitude", "variables: [q]\nparameters: {A: 1.5}\n"
                                                         "equations: [\"q'' + sin(q) = 0\"]\n"
                                                         "initial_state: {q: A, \"q'\": 0}\n");
  for (const double A : {1.5, 2.5}) {
    const auto j = Json("solve " + model + " --set A=" + std::to_string(A) + " --json");
    ASSERT_EQ(j["status"], "converged") << j.dump();
    const double exact = PendulumFrequency(A);
    EXPECT_NEAR(Frequency(j), exact, 1e-12 * exact) << A;
    const std::string note = j["frequency_note"];
    const double guess = std::stod(note.substr(note.find("w = ") + 4));
    EXPECT_NEAR(guess, exact, 1e-6 * exact) << note;
  }
  // A model moved to other parameters by the library (continuation, sweeps).
  const Model loaded = LoadModel(model);
  const double moved = PendulumFrequency(2.5);
  EXPECT_NEAR(WithParameters(loaded, {{"A", 2.5}}).problem.frequencies[0], moved, 1e-6 * moved);
  EXPECT_NEAR(ProblemWithParameters(loaded, {{"A", 2.5}}).frequencies[0], moved, 1e-6 * moved);
  std::remove(model.c_str());
}

// No period to read: an equilibrium, a flow without a time scale. Exit 2,
// the file and where initial_state is, what to give instead.
TEST(Defaults, NoTrajectoryGuessAtAnEquilibrium) {
  const std::string rest = WriteModel("rest", "variables: [x]\nequations: [\"x'' + x + x^3 = 0\"]\n"
                                              "initial_state: {x: 0, \"x'\": 0}\n");
  const auto r = Cli("solve " + rest);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(rest + ":3:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("initial_state is an equilibrium"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frequencies: [{guess: value}]"), std::string::npos) << r.out;
  const std::string drift = WriteModel("drift", "variables: [x]\nequations: [\"x' = 1\"]\ninitial_state: {x: 0}\n");
  const auto d = Cli("solve " + drift);
  EXPECT_EQ(d.code, 2) << d.out;
  EXPECT_NE(d.out.find("no time scale"), std::string::npos) << d.out;
  for (const std::string& f : {rest, drift}) std::remove(f.c_str());
}

// A forced pendulum file without a guess: the zero start fails at the start
// order, and the motion settled from rest is tried before raising the order
// from the zero start (which cost 1.5 s and failed). The same response as
// the benchmark's file with a hand guess near it, and the original equations
// integrated by CVODE from the solution's state stay on it.
TEST(Defaults, ForcedFileWithoutAGuessStartsFromTheSettledMotion) {
  const std::string model = WriteModel("fpend", "variables: [th]\nequations:\n"
                                                "  - \"th'' + 0.1*th' + sin(th) = 0.5*cos(0.8*t)\"\n"
                                                "frequencies: [0.8]\n");
  const auto j = Json("solve " + model + " --validate --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  EXPECT_EQ(j["start"].get<std::string>().rfind("simulation", 0), 0u) << j["start"];
  EXPECT_EQ(j["validation"]["status"], "ok");
  EXPECT_LT(j["validation"]["relative_error"].get<double>(), 1e-10);
  const auto hand = Json("solve tests/benchmarks/peers/models/forced-pendulum.yaml --json");
  ASSERT_EQ(hand["status"], "converged");
  for (const char* part : {"cos", "sin"})
    for (int k = 1; k <= 3; ++k)
      EXPECT_NEAR(j["coefficients"]["th"][part][k].get<double>(), hand["coefficients"]["th"][part][k].get<double>(),
                  1e-10)
          << part << k;
  std::remove(model.c_str());
}

// The same forced file without 'frequencies': the base is read off the
// forcing (cos(0.8 t)), and the answer is the named file's to the bit.
TEST(Defaults, AForcedFileNeedsNoFrequencies) {
  const std::string equation = "variables: [th]\nequations:\n  - \"th'' + 0.1*th' + sin(th) = 0.5*cos(0.8*t)\"\n";
  const std::string bare = WriteModel("fpend_bare", equation);
  const std::string named = WriteModel("fpend_named", equation + "frequencies: [0.8]\n");
  const auto a = Json("solve " + bare + " --validate --json");
  const auto b = Json("solve " + named + " --validate --json");
  ASSERT_EQ(a["status"], "converged") << a.dump();
  EXPECT_EQ(a["frequencies"], b["frequencies"]);
  EXPECT_EQ(a["coefficients"], b["coefficients"]);
  EXPECT_EQ(a["validation"]["status"], "ok");
  // A parameter stays a parameter: --set w moves the base.
  const std::string parameter = WriteModel(
      "fduff", "variables: [x]\nparameters: {w: 1.5}\nequations:\n  - \"x'' + 0.1*x' + x + x^3 = cos(w*t)\"\n");
  const auto c = Json("solve " + parameter + " --set w=1.2 --json");
  ASSERT_EQ(c["status"], "converged") << c.dump();
  EXPECT_EQ(c["frequencies"][0].get<double>(), 1.2);
  for (const std::string& f : {bare, named, parameter}) std::remove(f.c_str());
}

// A MEMS plate past pull-in: V / (1 - x)^2 has no equilibrium to oscillate
// about, the motion from rest reaches x = 1 at t = 2.716 (x' -> infinity).
// Not converged, exit 3, with the residual and where the motion ended; the
// simulated start used to take 10^7 integrator steps at the singularity
// (24 s in all, now under a second).
TEST(Defaults, APullInIsReportedNotSearched) {
  const std::string model = WriteModel("pullin", "variables: [x]\nparameters: {V: 0.2, W: 0.9}\nequations:\n"
                                                 "  - \"x'' + 0.02*x' + x = V/(1 - x)^2 * (1 + 0.5*cos(W*t))\"\n"
                                                 "frequencies: [W]\n");
  const auto r = Cli("solve " + model + " --json");
  EXPECT_EQ(r.code, 3) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "not_converged");
  const std::string note = j["start_note"];
  EXPECT_NE(note.find("singular there"), std::string::npos) << note;
  EXPECT_NE(note.find("from the guess at raised orders"), std::string::npos) << note;
  EXPECT_NE(note.find("at t = 2.71"), std::string::npos) << note;
  std::remove(model.c_str());
}

// A DAE (no default conditions: the closure test integrates ODEs) without
// conditions is refused up front with what to add, exit 2; it used to climb
// to order 100 and end "underdetermined".
TEST(Defaults, MissingConditionsOfADaeAreNamed) {
  const std::string model =
      WriteModel("dae", "variables: [x, z]\nequations: [\"x'' + x*z = 0\", \"z*(1 + x^2) = 1\"]\n"
                        "frequencies: [{guess: 0.8}]\ninitial_state: {x: 1.5, \"x'\": 0}\n");
  const CliRun r = Cli("solve " + model);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("unknown base frequencies 1, conditions at t = 0 0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("x'(0) = 0"), std::string::npos) << r.out;
  std::remove(model.c_str());
}

// The file's own conditions are kept as written: no defaults added.
TEST(Defaults, TheFilesOwnConditionsAreKept) {
  const std::string model = WriteModel("own", "variables: [x]\nequations: [\"x'' + x + x^3 = 0\"]\n"
                                              "frequencies: [{guess: 1}]\nconditions: [\"x(0) = 1\", \"x'(0) = 0\"]\n"
                                              "initial_state: {x: 1, \"x'\": 0}\n");
  const auto j = Json("solve " + model + " --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  EXPECT_FALSE(j.contains("default_conditions"));
  std::remove(model.c_str());
}

// The pendulum started on w/3 with its first harmonic at 3 w: Newton
// converges there (the same orbit written on a third of its frequency), and
// the summary refuses it, naming the factor; `--start auto` then restates it
// on 3 w and solves again (exact: pi / (2 K(sin^2(theta0 / 2)))).
TEST(Defaults, ASubMultipleOfTheFrequencyIsNotASolution) {
  const double exact = PendulumFrequency(1.5);
  const std::string model =
      WriteModel("third", "variables: [theta]\nequations: [\"theta'' + sin(theta) = 0\"]\n"
                          "frequencies: [{guess: " + std::to_string(exact / 3) + "}]\n"
                          "conditions: [\"theta(0) = 1.5\", \"theta'(0) = 0\"]\n"
                          "initial_state: {theta: 1.5, \"theta'\": 0}\nguess: {theta: \"1.5*cos(3*w*t)\"}\n");
  const CliRun r = Cli("solve " + model + " --start guess --order 30");
  EXPECT_EQ(r.code, 5) << r.out;
  EXPECT_NE(r.out.find("the orbit repeats 3 times per period"), std::string::npos) << r.out;
  const auto j = Json("solve " + model + " --json");
  ASSERT_EQ(j["status"], "converged") << j.dump();
  EXPECT_NEAR(Frequency(j), exact, 1e-12 * exact);
  EXPECT_EQ(j["start"], "guess, restated on 3 w");
  EXPECT_NE(j["start_note"].get<std::string>().find("repeats 3 times"), std::string::npos) << j.dump();
  std::remove(model.c_str());
}

}  // namespace
}  // namespace rmhb::testing
