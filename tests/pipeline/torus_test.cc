// Tori of a model beyond one solve (rmhb/pipeline/torus.h, the torus part
// of rmhb/pipeline/branch.h), against references that use no harmonic
// balance: exact Lyapunov exponents of linear systems, Liouville's formula
// (the exponents of a torus of x'' - eps (1 - x^2) x' + x = F cos(w t) sum
// to the time average of eps (1 - x^2); one is 0, so the other is known),
// and a tongue's edge against the phase slips of CVODE trajectories on
// either side of it. The model file is written for these tests, defaults
// only (tests/pipeline/models/weakly-forced-vdp.yaml).

#include "rmhb/pipeline/torus.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "integrators/cvode_integrator.h"
#include "integrators/lyapunov.h"
#include "rmhb/pipeline/analyze.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/solve.h"
#include "rmhb/pipeline/stability.h"

namespace rmhb {
namespace {

constexpr const char* kVdp = "tests/pipeline/models/weakly-forced-vdp.yaml";

// The model prepared as `rmhb solve --p order --basis diamond` does.
PreparedSolve OnDiamond(const Model& model, int order) {
  SolveSettings settings;
  settings.order = order;
  settings.shape = "diamond";
  settings.shape_given = true;
  return PrepareSolve(model, settings);
}

// `--continue name=from:to` from the prepared options.
ContinueOptions Range(const std::string& name, double from, double to, const PreparedSolve& prepared) {
  ContinueOptions o;
  o.parameter = name;
  o.from = from;
  o.to = to;
  o.harmonic_balance = prepared.options;
  return o;
}

// `rmhb solve FILE --stability` from the library: the file written here,
// defaults only.
struct SolvedFile {
  Model model;
  SolveSummary summary;
};
SolvedFile SolveFileWithStability(const std::string& name, const std::string& text) {
  const std::string file = ::testing::TempDir() + "/" + name;
  std::ofstream(file) << text;
  SolveSettings settings;
  settings.default_tol = SolveSettings::kDefaultTolerance;
  const PreparedSolve prepared = PrepareSolve(LoadModel(file, {}), settings);
  SolveOptions options;
  options.harmonic_balance = prepared.options;
  options.stability = true;
  SolvedFile out{prepared.model, SolveModel(prepared.model, prepared.guess, options)};
  std::remove(file.c_str());
  return out;
}

// <x'^2> over the torus by Parseval, from the coefficients of x.
double MeanSquareVelocity(const HarmonicSolution& s) {
  double sum = 0;
  for (int k = 1; k < s.basis().size(); ++k) {
    const double rate = s.basis().Frequency(k, s.frequencies());
    sum += 0.5 * rate * rate * s.coefficients().row(0).segment(2 * k - 1, 2).squaredNorm();
  }
  return sum;
}

constexpr const char* kRayleigh =
    "name: forced-rayleigh\nvariables: [x]\nparameters: {eps: 0.3, F: 0.4, w: 1.7}\n"
    "equations:\n  - \"x'' - SIGN*eps*(1 - x'^2)*x' + x = F*cos(w*t)\"\n"
    "frequencies:\n  - w\n  - {guess: 1}\nconditions:\n  - \"x(0) = 0\"\n"
    "guess: {x: \"1.15*sin(w2*t) + F/(1 - w^2)*cos(w*t)\"}\n";

std::string Rayleigh(const char* sign) {
  std::string text = kRayleigh;
  text.replace(text.find("SIGN"), 4, sign);
  return text;
}

// Hill's method on a torus (METHOD.md s.18) against Liouville's formula: for
// x'' - eps (1 - x'^2) x' + x = F cos(w t) the trace of the Jacobian is
// eps (1 - 3 x'^2), its average over the torus the sum of the exponents; one
// is the free angle's 0, so the other is eps (1 - 3 <x'^2>). The attracting
// torus (eps > 0) is stable by both methods; reversed in time (eps < 0) it
// repels: Hill's exponent changes sign, and the Lyapunov integration leaves
// the torus and says so rather than report the exponents of where it went.
TEST(Torus, HillExponentsOfATorusAreLiouvillesAndTheLyapunovVerdictAgrees) {
  for (const char* sign : {"1", "-1"}) {
    SCOPED_TRACE(sign);
    const SolvedFile f = SolveFileWithStability("rayleigh.yaml", Rayleigh(sign));
    ASSERT_TRUE(f.summary.converged()) << f.summary.FullReport();
    ASSERT_TRUE(f.summary.stability && f.summary.stability->hill && f.summary.stability->lyapunov);
    const StabilitySummary& st = *f.summary.stability;
    SCOPED_TRACE(st.FullReport());
    const HillStabilityReport& hill = *st.hill;
    ASSERT_EQ(hill.exponents.size(), 2u);
    ASSERT_EQ(hill.trivials.size(), 1u);
    EXPECT_LT(std::abs(hill.exponents[hill.trivial]), 1e-10);
    EXPECT_TRUE(hill.multipliers.empty());
    const double liouville = (sign[0] == '-' ? -0.3 : 0.3) * (1 - 3 * MeanSquareVelocity(f.summary.solution()));
    EXPECT_NEAR(hill.max_real_part, liouville, 1e-9);
    EXPECT_TRUE(st.agree());
    EXPECT_EQ(st.judged_by, "Hill, the trivial exponents left out");
    EXPECT_EQ(st.largest_exponent, hill.max_real_part);
    if (sign[0] == '1') {
      EXPECT_EQ(st.verdict, StabilityVerdict::kStable);
      ASSERT_TRUE(st.max_exponent_difference.has_value());
      EXPECT_LT(*st.max_exponent_difference, st.lyapunov->tolerance);
      EXPECT_LT(st.lyapunov->departure, 1e-6);
    } else {
      EXPECT_EQ(st.verdict, StabilityVerdict::kUnstable);
      EXPECT_EQ(st.lyapunov_verdict, StabilityVerdict::kUnstable);
      EXPECT_GT(st.lyapunov->departure, TorusStabilityReport::kLeftTorus);
      EXPECT_NE(st.lyapunov->message.find("left the torus"), std::string::npos);
      EXPECT_FALSE(st.max_exponent_difference.has_value());
    }
  }
}

// A conservative torus (two coupled Duffing oscillators, both frequencies
// unknown): every exponent of Hill's method on the imaginary axis to
// round-off, two of them the free angles', and the Lyapunov exponents
// within their tolerance of 0: neutral by both.
TEST(Torus, AConservativeTorusIsNeutralByHillAndLyapunov) {
  const SolvedFile f = SolveFileWithStability(
      "two_duffing.yaml",
      "name: two-duffing\nvariables: [x, y]\nparameters: {x0: 0.45, y0: 0.15}\n"
      "equations:\n  - \"x'' + x + 0.5*x^3 + 0.2*(x - y) = 0\"\n"
      "  - \"y'' + 1.6*y + 0.3*y^3 + 0.2*(y - x) = 0\"\n"
      "frequencies:\n  - {guess: 1.07}\n  - {guess: 1.36}\n"
      "conditions:\n  - \"x(0) = x0\"\n  - \"y(0) = y0\"\n  - \"x'(0) = 0\"\n"
      "  - \"y'(0) = 0\"\ninitial_state: {x: x0, \"x'\": 0, y: y0, \"y'\": 0}\n");
  ASSERT_TRUE(f.summary.converged()) << f.summary.FullReport();
  ASSERT_TRUE(f.summary.stability && f.summary.stability->hill && f.summary.stability->lyapunov);
  const StabilitySummary& st = *f.summary.stability;
  SCOPED_TRACE(st.FullReport());
  ASSERT_EQ(st.hill->exponents.size(), 4u);
  EXPECT_EQ(st.hill->trivials.size(), 2u);
  for (const auto& l : st.hill->exponents) EXPECT_LT(std::abs(l.real()), 1e-12);
  EXPECT_EQ(st.hill_verdict, StabilityVerdict::kNeutral);
  EXPECT_EQ(st.lyapunov_verdict, StabilityVerdict::kNeutral);
  EXPECT_EQ(st.lyapunov->trivial, 2);
  EXPECT_EQ(st.verdict, StabilityVerdict::kNeutral);
  EXPECT_TRUE(st.agree());
}

TEST(LyapunovExponents, LinearSystemsExactly) {
  // A damped rotation (-0.3 twice) and a growing mode (0.2): exact at any T.
  integrators::OdeSystem normal{3, [](double, const double* y, double* dy) {
                                  dy[0] = -0.3 * y[0] + y[1];
                                  dy[1] = -y[0] - 0.3 * y[1];
                                  dy[2] = 0.2 * y[2];
                                }};
  integrators::LyapunovOptions o;
  o.integrator.relative_tolerance = 1e-10;
  o.segment = 2;
  o.segments = 50;
  const auto r = integrators::LyapunovExponents(normal, Eigen::Vector3d(1, 0, 1), 0, o);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.exponents[0], 0.2, 1e-8);
  EXPECT_NEAR(r.exponents[1], -0.3, 1e-8);
  EXPECT_NEAR(r.exponents[2], -0.3, 1e-8);
  // Non-normal: the exponents -1, -2 come at a rate 1/T, which the spread shows.
  integrators::OdeSystem sheared{2, [](double, const double* y, double* dy) {
                                   dy[0] = -y[0] + 5 * y[1];
                                   dy[1] = -2 * y[1];
                                 }};
  o.segments = 100;
  const auto s = integrators::LyapunovExponents(sheared, Eigen::Vector2d(1, 1), 0, o);
  ASSERT_TRUE(s.ok);
  EXPECT_NEAR(s.exponents[0], -1, 3 * s.spread + 1e-9);
  EXPECT_NEAR(s.exponents[1], -2, 3 * s.spread + 1e-9);
  EXPECT_LT(s.spread, 0.02);
  EXPECT_THROW(integrators::LyapunovExponents(sheared, Eigen::Vector3d(1, 1, 1), 0, o), std::invalid_argument);
}

TEST(Torus, OutermostCoefficientsAreTheRimOfAnyIndexSet) {
  // Periodic, order 10, coefficient 10^-k at harmonic k: the rim is k = 9, 10.
  const HarmonicBasis basis = HarmonicBasis::Periodic(10);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(1, basis.num_coefficients());
  double all = 0;
  for (int k = 1; k <= 10; ++k) c(0, 2 * k - 1) = std::pow(10.0, -k), all += std::pow(10.0, -2 * k);
  const HarmonicSolution s(basis, {1.0}, c, {Variable{"x", VariableRole::kState, ""}});
  EXPECT_NEAR(OutermostCoefficients(s), std::sqrt((1e-18 + 1e-20) / all), 1e-22);
  // A diamond: only its two outer layers |m| + |n| = p - 1, p count.
  const HarmonicBasis diamond = HarmonicBasis::Diamond(2, 4);
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(1, diamond.num_coefficients());
  d(0, 2 * diamond.Find({1, 0}) - 1) = 1;
  d(0, 2 * diamond.Find({2, 1}) - 1) = 1e-3;  // level 3
  d(0, 2 * diamond.Find({1, 1}) - 1) = 1e-1;  // level 2: inside
  const HarmonicSolution t(diamond, {1.0, 0.7}, d, {Variable{"x", VariableRole::kState, ""}});
  EXPECT_NEAR(OutermostCoefficients(t), 1e-3 / std::sqrt(1 + 1e-2 + 1e-6), 1e-15);
}

TEST(Torus, LockedSolutionIsTheTorusAtTheRationalRotationNumber) {
  const HarmonicBasis basis = HarmonicBasis::Diamond(2, 4);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(2, basis.num_coefficients());
  for (int j = 0; j < c.cols(); ++j) c(0, j) = std::sin(1.0 + j), c(1, j) = std::cos(2.0 * j);
  const double w = 1.3;
  const Resonance lock{2, 3, 0};
  const HarmonicSolution torus(basis, {w, w * 2 / 3}, c, {Variable{"x", VariableRole::kState, ""}, Variable{"y", VariableRole::kState, ""}});
  const HarmonicSolution locked = LockedSolution(torus, lock, 0.4);
  const HarmonicSolution turned = torus.Shifted({0, 0.4});
  ASSERT_EQ(locked.frequencies().size(), 1u);
  EXPECT_DOUBLE_EQ(locked.frequencies()[0], w / 3);
  for (double t : {0.0, 0.7, 3.1, 11.9})
    for (int v = 0; v < 2; ++v) EXPECT_NEAR(locked.Value(v, t), turned.Value(v, t), 1e-13);
}

// Phase slips of the forced oscillator against the forcing over `window`
// periods after `transient` ones: 0 inside a 1:1 tongue, >= 1 outside it.
int PhaseSlips(double w, int transient, int window) {
  const double eps = 0.2, F = 0.1, T = 2 * M_PI / w;
  integrators::OdeSystem vdp{2, [&](double t, const double* y, double* dy) {
                               dy[0] = y[1];
                               dy[1] = eps * (1 - y[0] * y[0]) * y[1] - y[0] + F * std::cos(w * t);
                             }};
  integrators::IntegratorOptions o;
  o.relative_tolerance = 1e-9;
  o.absolute_tolerance = 1e-11;
  std::vector<double> times;
  for (int k = 0; k <= 16 * window; ++k) times.push_back((transient + k / 16.0) * T);
  const auto settle = integrators::IntegrateOde(vdp, Eigen::Vector2d(2, 0), 0, {transient * T}, o);
  const Eigen::VectorXd y0 = settle.trajectory.states.row(0).transpose();
  const auto r = integrators::IntegrateOde(vdp, y0, transient * T, times, o);
  double turned = 0, previous = std::atan2(-y0(1), y0(0));
  for (int k = 1; k < r.trajectory.states.rows(); ++k) {
    const double angle = std::atan2(-r.trajectory.states(k, 1), r.trajectory.states(k, 0));
    turned += std::remainder(angle - previous, 2 * M_PI);
    previous = angle;
  }
  return static_cast<int>(std::lround(window - turned / (2 * M_PI)));
}

TEST(Torus, ForcedBranchStableByLyapunovAndAcrossTheOneToOneTongue) {
  const PreparedSolve prepared = OnDiamond(LoadModel(kVdp, {{"w", 1.09}}), 16);
  ContinueOptions o = Range("w", 1.09, 1.0, prepared);
  o.tail_tolerance = 1e-4;
  o.steps = 5;  // the coefficients, not w, make the arclength: larger steps than w's range / 10
  o.max_step = 0.05;
  const BranchSummary b = ContinueModel(prepared.model, prepared.guess, o);
  ASSERT_GE(b.continuation.points.size(), 3u) << b.FullReport();
  // Every torus stable; Liouville: the transverse exponent is the average of
  // eps (1 - x^2) over the torus, eps (1 - <x^2>) by Parseval.
  for (size_t i = 0; i < b.continuation.points.size(); ++i) {
    const BranchPointReport& r = b.reports[i];
    ASSERT_TRUE(r.lyapunov && r.lyapunov->ok);
    EXPECT_EQ(r.stability, "stable") << r.lyapunov->BriefReport();
    const Eigen::MatrixXd& c = b.continuation.points[i].solution.coefficients();
    const double mean_square = c(0, 0) * c(0, 0) + 0.5 * c.row(0).tail(c.cols() - 1).squaredNorm();
    EXPECT_NEAR(r.lyapunov->max_exponent, 0.2 * (1 - mean_square), r.lyapunov->tolerance);
    EXPECT_LE(r.outermost, 1e-4 * (i + 1 == b.continuation.points.size() ? 2 : 1));
  }
  // The first torus judged by Hill's method too: the same verdict.
  EXPECT_NE(b.continuation.stability_cross_check.find("stable), Lyapunov"), std::string::npos)
      << b.continuation.stability_cross_check;
  EXPECT_NE(b.continuation.stability_cross_check.find("verdicts agree"), std::string::npos)
      << b.continuation.stability_cross_check;
  // The 1:1 tongue: its near edge a fold of the locked branch, checked by
  // CVODE 1e-4 to either side (no slip inside over 1500 periods, slips outside).
  ASSERT_EQ(b.tongues.size(), 1u) << b.FullReport();
  const TongueReport& t = b.tongues[0];
  EXPECT_EQ(t.lock.p, 1);
  EXPECT_EQ(t.lock.q, 1);
  ASSERT_TRUE(std::isfinite(t.near_edge)) << t.Describe("w");
  EXPECT_EQ(PhaseSlips(t.near_edge - 1e-4, 3000, 1500), 0);
  EXPECT_GE(PhaseSlips(t.near_edge + 1e-4, 3000, 1500), 1);
  EXPECT_EQ(b.status, BranchStatus::kCompleted) << b.message;  // locked to the end of the range
}

// Turns of y's phase against x's of two velocity-coupled Van der Pol
// oscillators (detuning d) over `window` time after `transient`: 0 inside
// their 1:1 tongue, >= 1 outside it. By CVODE from the in-phase state.
int CoupledSlips(double d, double transient, double window) {
  const double eps = 0.2, k = 0.05;
  integrators::OdeSystem pair{4, [&](double, const double* u, double* du) {
                                du[0] = u[1];
                                du[1] = eps * (1 - u[0] * u[0]) * u[1] - u[0] + k * (u[3] - u[1]);
                                du[2] = u[3];
                                du[3] = eps * (1 - u[2] * u[2]) * u[3] - (1 + d) * (1 + d) * u[2] + k * (u[1] - u[3]);
                              }};
  integrators::IntegratorOptions o;
  o.relative_tolerance = 1e-9;
  o.absolute_tolerance = 1e-11;
  const auto settle = integrators::IntegrateOde(pair, Eigen::Vector4d(2, 0, 2, 0), 0, {transient}, o);
  const Eigen::VectorXd u0 = settle.trajectory.states.row(0).transpose();
  std::vector<double> times;
  for (double t = transient + 0.25; t <= transient + window; t += 0.25) times.push_back(t);
  const auto r = integrators::IntegrateOde(pair, u0, transient, times, o);
  auto difference = [](const Eigen::VectorXd& u) { return std::atan2(-u(3), u(2)) - std::atan2(-u(1), u(0)); };
  double turned = 0, previous = difference(u0);
  for (int i = 0; i < r.trajectory.states.rows(); ++i) {
    const double now = difference(r.trajectory.states.row(i).transpose());
    turned += std::remainder(now - previous, 2 * M_PI);
    previous = now;
  }
  return static_cast<int>(std::lround(std::abs(turned) / (2 * M_PI)));
}

// Two velocity-coupled Van der Pol oscillators, the second detuned by d: a
// model file written here, both frequencies unknown.
Model CoupledVdp(double d) {
  const std::string file = ::testing::TempDir() + "/coupled_vdp.yaml";
  std::ofstream(file) << "name: velocity-coupled-vdp\nvariables: [x, y]\nparameters: {eps: 0.2, k: 0.05, d: 0.15}\n"
                         "equations:\n  - \"x'' - eps*(1 - x^2)*x' + x = k*(y' - x')\"\n"
                         "  - \"y'' - eps*(1 - y^2)*y' + (1 + d)^2*y = k*(x' - y')\"\n"
                         "frequencies:\n  - {guess: 1}\n  - {guess: 1.15}\n"
                         "conditions:\n  - \"x'(0) = 0\"\n  - \"y'(0) = 0\"\n"
                         "guess: {x: \"2*cos(w1*t)\", y: \"2*cos(w2*t)\"}\n"
                         "initial_state: {x: 2, \"x'\": 0, y: 2, \"y'\": 0}\n";
  Model model = LoadModel(file, {{"d", d}});
  std::remove(file.c_str());
  return model;
}

// Locking of an autonomous torus (both frequencies unknown): two
// velocity-coupled Van der Pol oscillators, the second detuned by d, in a
// model file written here. Along d from 0.15 to -0.15 the torus meets the
// 1:1 tongue; the locked orbit (one unknown frequency, the first phase
// condition kept) is followed to its folds, the tongue's edges, each checked
// by CVODE 1e-4 to either side (no slip inside over 8000 time units, slips
// outside), and the torus is resumed past the far edge and traced to the end.
TEST(Torus, AnAutonomousTorusLocksAcrossTheOneToOneTongue) {
  const Model model = CoupledVdp(0.15);
  EXPECT_TRUE(IsAutonomousTorus(model));
  const PreparedSolve prepared = OnDiamond(model, 10);
  ContinueOptions o = Range("d", 0.15, -0.15, prepared);
  o.tail_tolerance = 1e-3;
  o.stability = false;  // the forced branch's test has the Lyapunov verdicts
  const BranchSummary b = ContinueModel(prepared.model, prepared.guess, o);
  ASSERT_EQ(b.tongues.size(), 1u) << b.FullReport();
  const TongueReport& t = b.tongues[0];
  EXPECT_EQ(t.lock.p, 1);
  EXPECT_EQ(t.lock.q, 1);
  ASSERT_TRUE(std::isfinite(t.near_edge) && std::isfinite(t.far_edge)) << t.Describe("d");
  // The locked orbit: one unknown frequency, between the two oscillators'.
  ASSERT_FALSE(t.locked.empty());
  const HarmonicSolution& locked = t.locked[0].points.front().solution;
  ASSERT_EQ(locked.frequencies().size(), 1u);
  EXPECT_NEAR(locked.frequencies()[0], 1.0, 0.05);
  EXPECT_EQ(CoupledSlips(t.near_edge - 1e-4, 1000, 8000), 0) << t.Describe("d");
  EXPECT_GE(CoupledSlips(t.near_edge + 1e-4, 1000, 8000), 1) << t.Describe("d");
  EXPECT_EQ(CoupledSlips(t.far_edge + 1e-4, 1000, 8000), 0) << t.Describe("d");
  EXPECT_GE(CoupledSlips(t.far_edge - 1e-4, 1000, 8000), 1) << t.Describe("d");
  EXPECT_TRUE(t.crossed);
  EXPECT_LT(t.resumed_at, t.far_edge);
  EXPECT_EQ(b.status, BranchStatus::kCompleted) << b.message;
  const HarmonicSolution& last = b.continuation.points.back().solution;
  EXPECT_EQ(last.frequencies().size(), 2u);
  EXPECT_DOUBLE_EQ(b.continuation.points.back().parameter, -0.15);
}

// A conservative 2-DOF model file written here (not bundled), both
// frequencies unknown, continued with defaults (as rmhb solve --continue):
// the first point's adaptive index set and its detected reflection are kept
// along the branch, the set is enriched where the torus outgrows it (a tail
// tolerance of 1e-11: twice on this stretch), and every point is a true torus
// (CVODE over the slowest period) at the target's accuracy.
TEST(Torus, BranchOfAModelFileOnTheAdaptiveIndexSet) {
  const std::string file = ::testing::TempDir() + "/two_duffing.yaml";
  std::ofstream(file) << "name: two-duffing\nvariables: [x, y]\nparameters: {x0: 0.45, y0: 0.15}\n"
                         "equations:\n  - \"x'' + x + 0.5*x^3 + 0.2*(x - y) = 0\"\n"
                         "  - \"y'' + 1.6*y + 0.3*y^3 + 0.2*(y - x) = 0\"\n"
                         "frequencies:\n  - {guess: 1.07}\n  - {guess: 1.36}\n"
                         "conditions:\n  - \"x(0) = x0\"\n  - \"y(0) = y0\"\n  - \"x'(0) = 0\"\n"
                         "  - \"y'(0) = 0\"\ninitial_state: {x: x0, \"x'\": 0, y: y0, \"y'\": 0}\n";
  SolveSettings settings;
  settings.default_torus_tol = SolveSettings::kDefaultTolerance;
  const PreparedSolve prepared = PrepareSolve(LoadModel(file, {}), settings);
  EXPECT_EQ(prepared.options.shape, BasisShape::kAdaptive);
  ContinueOptions o;
  o.parameter = "x0";
  o.from = 0.45;
  o.to = 0.62;
  o.steps = 3;
  o.stability = false;
  o.validate = true;
  o.tail_tolerance = 1e-11;
  o.harmonic_balance = prepared.options;
  const BranchSummary b = ContinueModel(prepared.model, prepared.guess, o);
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  ASSERT_GE(b.enrichments.size(), 1u) << b.FullReport();
  const auto& points = b.continuation.points;
  ASSERT_GE(points.size(), 4u);
  int previous = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const HarmonicBasis& basis = points[i].solution.basis();
    EXPECT_EQ(basis.shape(), "adaptive");
    EXPECT_GE(basis.size(), previous) << i;
    previous = basis.size();
    EXPECT_LE(points[i].residual, 1e-14) << i;
    EXPECT_LE(b.reports[i].validation_error, 1e-8 * b.reports[i].peak) << i;
    EXPECT_LE(b.reports[i].outermost, 1e-11) << i;
    // The reflection (x, y) -> -(x, y) with both angles turned by pi stays
    // exact: every harmonic with m + n even is zero.
    const Eigen::MatrixXd& c = points[i].solution.coefficients();
    for (int k = 0; k < basis.size(); ++k) {
      if ((basis.harmonic(k)[0] + basis.harmonic(k)[1]) % 2 != 0) continue;
      for (int col : {2 * k - 1, 2 * k}) {
        if (col < 0) continue;
        EXPECT_EQ(c.col(col).cwiseAbs().maxCoeff(), 0.0) << i << " harmonic " << k;
      }
    }
  }
  EXPECT_GT(previous, b.enrichments.front().before);
  std::remove(file.c_str());
}

TEST(Torus, AnalyzeSaysLockedOrQuasiPeriodicAndSolvesThatOne) {
  AnalyzeOptions o;
  o.solve.order = 20;
  const AnalyzeSummary locked = Analyze(LoadModel(kVdp, {{"w", 1.0}}), o);
  EXPECT_EQ(locked.motion.rfind("locked 1:1", 0), 0u) << locked.motion;
  ASSERT_TRUE(locked.ok()) << locked.FullReport();
  EXPECT_EQ(locked.solve->solution->frequencies().size(), 1u);
  EXPECT_DOUBLE_EQ(locked.solve->solution->frequencies()[0], 1.0);
  const AnalyzeSummary torus = Analyze(LoadModel(kVdp, {{"w", 1.15}}), o);
  EXPECT_EQ(torus.motion.rfind("quasi-periodic", 0), 0u) << torus.motion;
  ASSERT_TRUE(torus.solve && torus.solve->usable()) << torus.FullReport();
  EXPECT_EQ(torus.solve->solution->frequencies().size(), 2u);
}

// The same for an autonomous torus model (two coupled oscillators, both
// frequencies unknown): inside the 1:1 tongue (d = 0.02, its edge at 0.050)
// one base frequency explains the motion and the periodic orbit is solved
// and validated; outside (d = 0.1) one base carries half the line energy and
// the torus is solved.
TEST(Torus, AnalyzeSaysWhenAnAutonomousTorusIsLocked) {
  auto analyze = [](double d) {  // as rmhb analyze FILE: defaults only
    SolveSettings settings;
    settings.default_tol = SolveSettings::kDefaultTolerance;
    const PreparedSolve prepared = PrepareSolve(CoupledVdp(d), settings);
    AnalyzeOptions o;
    o.solve = prepared.options;
    return Analyze(prepared.model, o);
  };
  const AnalyzeSummary locked = analyze(0.02);
  EXPECT_EQ(locked.motion.rfind("locked: one base frequency", 0), 0u) << locked.motion;
  ASSERT_TRUE(locked.ok()) << locked.FullReport();
  ASSERT_EQ(locked.solve->solution->frequencies().size(), 1u);
  EXPECT_NEAR(locked.solve->solution->frequencies()[0], locked.seed->frequencies[0], 1e-9);
  EXPECT_EQ(CoupledSlips(0.02, 1000, 3000), 0);
  const AnalyzeSummary torus = analyze(0.1);
  EXPECT_EQ(torus.motion.rfind("quasi-periodic", 0), 0u) << torus.motion;
  ASSERT_TRUE(torus.ok()) << torus.FullReport();
  EXPECT_EQ(torus.solve->solution->frequencies().size(), 2u);
  EXPECT_GE(CoupledSlips(0.1, 1000, 3000), 1);
}

}  // namespace
}  // namespace rmhb
