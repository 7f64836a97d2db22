#include "examples/example_system.h"

#include <cmath>
#include <complex>
#include <stdexcept>

#include "examples/quasi_periodic_guess.h"
#include "examples/references.h"
#include "examples/simulation_guess.h"

namespace rmhb::examples {
namespace {

using Values = std::map<std::string, double>;

Polynomial P(const PolynomialSystem& s, const char* name) { return s.Var(name); }

// (A fixed-size vector assigned to a VectorXd trips GCC 12's -Warray-bounds
// under AVX.)
Eigen::VectorXd State(std::initializer_list<double> values) {
  Eigen::VectorXd y(values.size());
  int i = 0;
  for (double v : values) y(i++) = v;
  return y;
}

// x'' + c x' + k x + a x^3 = F cos(w t), recast x' = v (phi = 3).
ExampleSetup Duffing(const Values& p) {
  const double c = p.at("c"), k = p.at("k"), a = p.at("a"), F = p.at("F"), w = p.at("w");
  if (!(w > 0)) throw std::invalid_argument("duffing: w must be > 0");
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v");
  const Polynomial x = P(s, "x"), v = P(s, "v");
  s.AddEquation(s.D("x") - v);
  s.AddEquation(s.D("v") + c * v + k * x + a * Pow(x, 3) - Polynomial::Cos({1}, F));
  ExampleSetup e{{s, {w}, {false}, {}},
                 HarmonicSolution(HarmonicBasis::Periodic(1), {w}, Eigen::MatrixXd::Zero(2, 3),
                                  s.variables()),
                 {},
                 {},
                 20};
  // One-harmonic balance as the guess: with K = k - w^2 + 3/4 a A^2 the
  // amplitude solves (K^2 + c^2 w^2) A^2 = F^2; take the largest root (the
  // resonant branch), found by scanning y = A^2 and bisecting.
  auto amplitude_eq = [&](double y) {
    const double K = k - w * w + 0.75 * a * y;
    return (K * K + c * c * w * w) * y - F * F;
  };
  double y_root = 0;
  const double y_max = 4 * (std::abs(F) / std::max(1e-3, std::abs(c * w)) + 1) *
                       (std::abs(F) / std::max(1e-3, std::abs(c * w)) + 1);
  for (int i = 4000; i > 0 && y_root == 0; --i) {
    double lo = y_max * (i - 1) / 4000, hi = y_max * i / 4000;
    if (amplitude_eq(lo) * amplitude_eq(hi) > 0) continue;
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (lo + hi);
      (amplitude_eq(lo) * amplitude_eq(mid) <= 0 ? hi : lo) = mid;
    }
    y_root = 0.5 * (lo + hi);
  }
  const double K = k - w * w + 0.75 * a * y_root, D = K * K + c * c * w * w;
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2, 3);
  if (D > 0) {
    g(0, 1) = F * K / D;
    g(0, 2) = F * c * w / D;
  }
  g(1, 1) = w * g(0, 2);
  g(1, 2) = -w * g(0, 1);
  e.guess = HarmonicSolution(HarmonicBasis::Periodic(1), {w}, g, s.variables());
  e.original.names = {"x", "x'"};
  e.original.rhs = [=](double t, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = F * std::cos(w * t) - c * y[1] - k * y[0] - a * y[0] * y[0] * y[0];
  };
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Derivative(0, t)).eval();
  };
  return e;
}

// Free Van der Pol x'' - eps (1 - x^2) x' + x = 0: derivative coupling, x' = u
// and u' = eps u - x - eps x^2 u (phi = 3). Unknown frequency; phase x'(0) = 0.
ExampleSetup VanDerPol(const Values& p) {
  const double eps = p.at("eps");
  if (!(eps > 0) || eps > 1000) throw std::invalid_argument("vanderpol: eps must be in (0, 1000]");
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("u", VariableRole::kState, "x'");
  const Polynomial x = P(s, "x"), u = P(s, "u");
  s.AddEquation(s.D("x") - u);
  s.AddEquation(s.D("u") - eps * u + x + eps * x * x * u);
  ExampleSetup e{{s, {1.0}, {true}, {PointCondition::Value(1, 0.0, "x'(0) = 0 (phase)")}},
                 HarmonicSolution(HarmonicBasis::Periodic(1), {1.0}, Eigen::MatrixXd::Zero(2, 3),
                                  s.variables()),
                 {},
                 {},
                 eps <= 1 ? 40 : static_cast<int>(40 * eps)};
  auto rhs = [eps](double, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = eps * (1 - y[0] * y[0]) * y[1] - y[0];
  };
  const double period_guess = 2 * M_PI + 1.614 * eps;  // sinusoid + relaxation estimate
  e.guess = GuessFromSimulation(rhs, Eigen::Vector2d(2.0, 0.0), period_guess, 3,
                                HarmonicBasis::Periodic(e.default_order),
                                s.variables(), [](const Eigen::VectorXd& y) { return y; });
  e.problem.frequencies = e.guess.frequencies();
  e.original.names = {"x", "x'"};
  e.original.rhs = rhs;
  // Adams at rtol 1e-13 beats BDF (order <= 5) by orders of magnitude here
  // until the relaxation gets really stiff.
  e.original.stiff = eps > 20;
  e.original.initial_state = State({2.0, 0.0});
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Value(1, t)).eval();
  };
  return e;
}

// Pendulum theta'' + sin(theta) = 0, recast (20): theta' = v, v' = -s,
// s' = c v, c' = -s v with s = sin(theta), c = cos(theta) (phi = 2).
// s and c are defined through their derivatives, so their constant balance is
// dropped and their values at t = 0 pinned (24). Conditions theta(0) = theta0,
// theta'(0) = 0: overdetermined by one but consistent (energy conservation).
ExampleSetup Pendulum(const Values& p) {
  const double a = p.at("theta0");
  if (!(std::abs(a) > 0 && std::abs(a) < M_PI))
    throw std::invalid_argument("pendulum: theta0 must satisfy 0 < |theta0| < pi");
  PolynomialSystem s;
  s.AddVariable("theta");
  s.AddVariable("v", VariableRole::kState, "theta'");
  s.AddVariable("s", VariableRole::kAuxiliary, "sin(theta)");
  s.AddVariable("c", VariableRole::kAuxiliary, "cos(theta)");
  const Polynomial v = P(s, "v"), sn = P(s, "s"), cs = P(s, "c");
  s.AddEquation(s.D("theta") - v);
  s.AddEquation(s.D("v") + sn);
  s.AddEquation(s.D("s") - cs * v, false);
  s.AddEquation(s.D("c") + sn * v, false);
  const double w0 = 1.0 - a * a / 16.0;
  std::vector<PointCondition> conditions = {
      PointCondition::Value(0, a, "theta(0) = theta0"),
      PointCondition::Value(1, 0.0, "theta'(0) = 0"),
      PointCondition::Pinned(2, 0, [](double th) { return std::sin(th); },
                             [](double th) { return std::cos(th); }, "s(0) = sin(theta(0))"),
      PointCondition::Pinned(3, 0, [](double th) { return std::cos(th); },
                             [](double th) { return -std::sin(th); }, "c(0) = cos(theta(0))")};
  ExampleSetup e{{s, {w0}, {true}, conditions},
                 HarmonicSolution::FromAngles(
                     HarmonicBasis::Periodic(5), {w0}, s.variables(),
                     [a, w0](const std::vector<double>& th) {
                       const double theta = a * std::cos(th[0]);
                       return Eigen::Vector4d(theta, -a * w0 * std::sin(th[0]), std::sin(theta),
                                              std::cos(theta))
                           .eval();
                     }),
                 {},
                 {},
                 25};
  e.original.names = {"theta", "theta'"};
  e.original.initial_state = State({a, 0.0});
  e.original.variables = [](const Eigen::VectorXd& y) {
    return Eigen::Vector4d(y(0), y(1), std::sin(y(0)), std::cos(y(0))).eval();
  };
  e.original.rhs = [](double, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = -std::sin(y[0]);
  };
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Value(1, t)).eval();
  };
  e.reference.frequency = PendulumFrequency(a);
  e.reference.amplitude = std::abs(a);
  e.reference.amplitude_variable = "theta";
  e.reference.solution = [a](double t) { return PendulumAngle(a, t); };
  e.reference.source = "exact: w = pi/(2K(m)), theta(t) from its nome series";
  return e;
}

// Relativistic oscillator x'' + (1 - x'^2)^(3/2) x = 0, recast (18):
// x' - v = 0, v' + u^3 x = 0, u^2 + v^2 - 1 = 0 (phi = 4), x(0) = 0, x'(0) = beta.
ExampleSetup Relativistic(const Values& p) {
  const double beta = p.at("beta");
  if (!(beta > 0 && beta < 1)) throw std::invalid_argument("relativistic: beta must be in (0, 1)");
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v", VariableRole::kState, "x'");
  s.AddVariable("u", VariableRole::kAuxiliary, "sqrt(1 - x'^2)");
  const Polynomial x = P(s, "x"), v = P(s, "v"), u = P(s, "u");
  s.AddEquation(s.D("x") - v);
  s.AddEquation(s.D("v") + Pow(u, 3) * x);
  s.AddEquation(u * u + v * v - 1.0);
  const double A = RelativisticAmplitude(beta);
  const double w0 = beta / A;
  std::vector<PointCondition> conditions = {
      PointCondition::Value(0, 0.0, "x(0) = 0"),
      PointCondition::DerivativeValue(0, beta, "x'(0) = beta")};
  ExampleSetup e{{s, {w0}, {true}, conditions},
                 HarmonicSolution::FromAngles(
                     HarmonicBasis::Periodic(5), {w0}, s.variables(),
                     [A, w0](const std::vector<double>& th) {
                       const double v = A * w0 * std::cos(th[0]);
                       return Eigen::Vector3d(A * std::sin(th[0]), v, std::sqrt(1 - v * v)).eval();
                     }),
                 {},
                 {},
                 55};
  e.original.names = {"x", "x'"};
  e.original.rhs = [](double, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = -std::pow(1 - y[1] * y[1], 1.5) * y[0];
  };
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Value(1, t)).eval();
  };
  e.original.initial_state = State({0.0, beta});
  e.original.variables = [](const Eigen::VectorXd& y) {
    return Eigen::Vector3d(y(0), y(1), std::sqrt(1 - y(1) * y(1))).eval();
  };
  e.reference.frequency = 2 * M_PI / RelativisticPeriod(beta);
  e.reference.amplitude = A;
  e.reference.amplitude_variable = "x";
  e.reference.source = "exact: energy gamma + x^2/2 conserved, period by quadrature";
  return e;
}

// Rayleigh-Plesset (16): R R'' = -3/2 R'^2 - A R'/R - B/R + C/R^3 + D - E cos(w t).
// Recast with v = R', x = 1/R: v' = -3/2 v^2 x - A v x^2 - B x^2 + C x^4 + D x
// - E x cos(w t), R x - 1 = 0 (phi = 4).
ExampleSetup RayleighPlesset(const Values& p) {
  const double A = p.at("A"), B = p.at("B"), C = p.at("C"), D = p.at("D"), E = p.at("E"),
               w = p.at("w");
  if (!(w > 0)) throw std::invalid_argument("rayleigh-plesset: w must be > 0");
  PolynomialSystem s;
  s.AddVariable("R");
  s.AddVariable("v", VariableRole::kState, "R'");
  s.AddVariable("x", VariableRole::kAuxiliary, "1/R");
  const Polynomial R = P(s, "R"), v = P(s, "v"), x = P(s, "x");
  s.AddEquation(s.D("R") - v);
  s.AddEquation(s.D("v") + 1.5 * v * v * x + A * v * x * x + B * x * x - C * Pow(x, 4) - D * x +
                x * Polynomial::Cos({1}, E));
  s.AddEquation(R * x - 1.0);
  // Equilibrium radius (E = 0) as the guess: -B/R + C/R^3 + D = 0 near R = 1.
  double R0 = 1.0;
  for (int i = 0; i < 50; ++i) {
    const double f = -B / R0 + C / (R0 * R0 * R0) + D, df = B / (R0 * R0) - 3 * C / std::pow(R0, 4);
    if (df == 0) break;
    R0 = std::max(0.1 * R0, R0 - f / df);
  }
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(3, 3);
  g(0, 0) = R0;
  g(2, 0) = 1 / R0;
  ExampleSetup e{{s, {w}, {false}, {}},
                 HarmonicSolution(HarmonicBasis::Periodic(1), {w}, g, s.variables()),
                 {},
                 {},
                 30};
  e.original.names = {"R", "R'"};
  e.original.variables = [](const Eigen::VectorXd& y) {
    return Eigen::Vector3d(y(0), y(1), 1 / y(0)).eval();
  };
  e.original.rhs = [=](double t, const double* y, double* dy) {
    const double r = y[0], rd = y[1];
    dy[0] = rd;
    dy[1] = (-1.5 * rd * rd - A * rd / r - B / r + C / (r * r * r) + D - E * std::cos(w * t)) / r;
  };
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Value(1, t)).eval();
  };
  return e;
}

// Asymmetric pendulum (25): second derivatives inside the nonlinear terms,
// kept implicit (phi = 3): with x' = p, y' = q,
//   p' + (1-k) x + (1-k)(x p^2 + x q^2 + x y q' + x^2 p') = 0
//   q' + y + (y q^2 + y p^2 + x y p' + y^2 q') = 0.
// Quasi-periodic on a 2-torus: both base frequencies unknown, the initial
// state (4 conditions) fixes the torus and its phases; overdetermined by two
// but consistent (two phase symmetries, two actions).
//
// The bases are the main frequencies of x and y, w1 ~ w2 ~ 1: a 1:1 internal
// resonance. The motion is a fast oscillation modulated by the slow beat
// w2 - w1 (energy exchange between x and y), so the spectrum spreads along
// the slow direction: x has m w1 + n w2 with n even, y with n odd, m + n odd
// (cubic nonlinearity), and the coefficients fall by only ~3 per step of n
// but by ~100 per step of 2 in m + n. The paper's diamond |m| + |n| <= p
// reaches slow index n only at p ~ 2n: at p = 5 with the frequencies solved
// for, the error over [0, 2000] is still 8.4e-2 (the paper, with FFT ones,
// 9.21e-3). The solve's adaptive index set (METHOD.md s.8) follows the
// spectrum instead, and the reflections the orbit keeps are detected on the
// equations (DetectHalfTurnSymmetries): nothing here is specific to it, and
// examples/models/asym-pendulum.yaml gives the same answer.

ExampleSetup AsymmetricPendulum(const Values& p) {
  const double k = p.at("kappa"), x0 = p.at("x0"), y0 = p.at("y0");
  if (!(k >= 0 && k < 1)) throw std::invalid_argument("asym-pendulum: kappa must be in [0, 1)");
  if (!(std::abs(x0) < 0.5 && std::abs(y0) < 0.5 && x0 != 0 && y0 != 0))
    throw std::invalid_argument("asym-pendulum: need 0 < |x0|, |y0| < 0.5");
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("y");
  s.AddVariable("p", VariableRole::kState, "x'");
  s.AddVariable("q", VariableRole::kState, "y'");
  const Polynomial x = P(s, "x"), y = P(s, "y"), vp = P(s, "p"), vq = P(s, "q");
  const Polynomial dp = s.D("p"), dq = s.D("q");
  s.AddEquation(s.D("x") - vp);
  s.AddEquation(s.D("y") - vq);
  s.AddEquation(dp + (1 - k) * x + (1 - k) * (x * vp * vp + x * vq * vq + x * y * dq + x * x * dp));
  s.AddEquation(dq + y + (y * vq * vq + y * vp * vp + x * y * dp + y * y * dq));
  std::vector<PointCondition> conditions = {
      PointCondition::Value(0, x0, "x(0) = x0"), PointCondition::Value(1, y0, "y(0) = y0"),
      PointCondition::Value(2, 0.0, "x'(0) = 0"), PointCondition::Value(3, 0.0, "y'(0) = 0")};
  auto rhs = [k](double, const double* z, double* dz) {
    // The second derivatives appear linearly: solve the 2x2 mass-matrix system.
    const double x = z[0], y = z[1], p = z[2], q = z[3];
    const double a11 = 1 + (1 - k) * x * x, a12 = (1 - k) * x * y;
    const double a21 = x * y, a22 = 1 + y * y;
    const double b1 = -(1 - k) * (x + x * p * p + x * q * q);
    const double b2 = -(y + y * q * q + y * p * p);
    const double det = a11 * a22 - a12 * a21;
    dz[0] = p;
    dz[1] = q;
    dz[2] = (b1 * a22 - a12 * b2) / det;
    dz[3] = (a11 * b2 - a21 * b1) / det;
  };
  // Guess: the linear modes x0 cos(w1 t), y0 cos(w2 t) at the paper's FFT
  // frequencies, as the model file writes it.
  const std::vector<double> w = {0.9857, 0.9935};
  const HarmonicBasis linear = HarmonicBasis::Diamond(2, 1);
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(4, linear.num_coefficients());
  const int k10 = linear.Find({1, 0}), k01 = linear.Find({0, 1});
  g(0, 2 * k10 - 1) = x0;
  g(1, 2 * k01 - 1) = y0;
  g(2, 2 * k10) = -w[0] * x0;
  g(3, 2 * k01) = -w[1] * y0;
  const HarmonicSolution guess(linear, w, g, s.variables());
  ExampleSetup e{{s, w, {true, true}, conditions}, guess, {}, {}, 7};
  e.original.names = {"x", "y", "x'", "y'"};
  e.original.initial_state = State({x0, y0, 0, 0});
  e.original.rhs = rhs;
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector4d(h.Value(0, t), h.Value(1, t), h.Value(2, t), h.Value(3, t)).eval();
  };
  return e;
}

// Forced Van der Pol x'' - eps (1 - x^2) x' + x = F cos(w t): with the
// forcing away from the natural frequency and not too strong, the response
// is quasi-periodic: base w1 = w (known, the forcing) and w2 near the limit
// cycle's frequency (unknown). One phase condition x'(0) = 0 fixes theta_2.
//
// The defaults (eps 0.2, F 0.5, w 2.3) are not locked, checked by
// simulation: w2 = 0.9974662549 +- 3e-10 measured over three windows from
// t = 300 to 6300 (w1/w2 = 2.3058424, no nearby ratio of small integers:
// 30/13 is 1.8e-3 away), and the stroboscopic map at the forcing period has
// no period up to 100 (max |x_{n+q} - x_n| >= 0.058 for every q <= 100).
// The system is odd with the forcing shifted by half a period, and the
// torus keeps that symmetry: only harmonics with m + n odd.
ExampleSetup ForcedVanDerPol(const Values& p) {
  const double eps = p.at("eps"), F = p.at("F"), w = p.at("w");
  if (!(eps > 0) || eps > 10) throw std::invalid_argument("forced-vanderpol: eps must be in (0, 10]");
  if (!(w > 0)) throw std::invalid_argument("forced-vanderpol: w must be > 0");
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("u", VariableRole::kState, "x'");
  const Polynomial x = P(s, "x"), u = P(s, "u");
  s.AddEquation(s.D("x") - u);
  s.AddEquation(s.D("u") - eps * u + x + eps * x * x * u - Polynomial::Cos({1, 0}, F));
  auto rhs = [=](double t, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = eps * (1 - y[0] * y[0]) * y[1] - y[0] + F * std::cos(w * t);
  };
  // Guess: the free limit cycle 2 cos(w2 t) and the linear forced response
  // F / (1 - w^2) cos(w t), as the model file writes it. The solve detects
  // the symmetry (x -> -x with the forcing half a period on: odd m + n) and
  // chooses its index set (METHOD.md s.8).
  const double w_free = 1.0 - eps * eps / 16.0;
  const HarmonicBasis linear = HarmonicBasis::Diamond(2, 1);
  Eigen::MatrixXd g = Eigen::MatrixXd::Zero(2, linear.num_coefficients());
  const int k10 = linear.Find({1, 0}), k01 = linear.Find({0, 1});
  g(0, 2 * k10 - 1) = F / (1 - w * w);
  g(0, 2 * k01 - 1) = 2;
  g(1, 2 * k10) = -w * F / (1 - w * w);
  g(1, 2 * k01) = -w_free * 2;
  const HarmonicSolution guess(linear, {w, w_free}, g, s.variables());
  ExampleSetup e{{s, guess.frequencies(), {false, true}, {PointCondition::Value(1, 0.0, "x'(0) = 0 (phase of theta_2)")}},
                 guess, {}, {}, 7};
  e.original.names = {"x", "x'"};
  e.original.initial_state = State({2.0, 0.0});
  e.original.rhs = rhs;
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Value(1, t)).eval();
  };
  return e;
}

// Duffing forced by two tones, x'' + c x' + k x + a x^3 = F1 cos(w1 t) +
// F2 cos(w2 t): two known base frequencies, no conditions. With a rational
// ratio w1 : w2 = r1 : r2 the response is periodic with period 2 pi / gcd,
// so the GCD rule (Theorem 2) applies beside the torus grid. The two are the
// same projection only while no two harmonics of the products share a
// frequency: the resonance r2 w1 - r1 w2 = 0 (order r1 + r2) must lie beyond
// the products' reach, r1 + r2 > (phi + 1) p for the diamond. Otherwise the
// GCD rule solves the periodic problem (right for that ratio) and the torus
// grid the quasi-periodic one, which differ by the resonant coefficients.
// Defaults 0.7 : 1.1 = 7 : 11 (order 18) keep them equal up to p = 4.
// Odd with both tones half a period on: only harmonics with m + n odd.
ExampleSetup DuffingTwoTone(const Values& p) {
  const double c = p.at("c"), k = p.at("k"), a = p.at("a"), F1 = p.at("F1"), F2 = p.at("F2"),
               w1 = p.at("w1"), w2 = p.at("w2");
  if (!(w1 > 0 && w2 > 0)) throw std::invalid_argument("duffing-2tone: w1, w2 must be > 0");
  PolynomialSystem s;
  s.AddVariable("x");
  s.AddVariable("v", VariableRole::kState, "x'");
  const Polynomial x = P(s, "x"), v = P(s, "v");
  s.AddEquation(s.D("x") - v);
  s.AddEquation(s.D("v") + c * v + k * x + a * Pow(x, 3) - Polynomial::Cos({1, 0}, F1) -
                Polynomial::Cos({0, 1}, F2));
  // Guess: the linear response to each tone.
  auto linear = [&](double F, double w) {
    return F / std::complex<double>(k - w * w, c * w);
  };
  const std::complex<double> X1 = linear(F1, w1), X2 = linear(F2, w2);
  HarmonicSolution guess = HarmonicSolution::FromAngles(
      HarmonicBasis::Diamond(2, 1), {w1, w2}, s.variables(), [=](const std::vector<double>& th) {
        const std::complex<double> e1 = std::polar(1.0, th[0]), e2 = std::polar(1.0, th[1]);
        const std::complex<double> i(0, 1);
        return Eigen::Vector2d((X1 * e1 + X2 * e2).real(),
                               (i * w1 * X1 * e1 + i * w2 * X2 * e2).real())
            .eval();
      });
  ExampleSetup e{{s, {w1, w2}, {false, false}, {},
                  {{{1, 1}, {-1, -1}, "x -> -x with both tones half a period on: odd m + n"}}},
                 guess, {}, {}, 4};
  e.original.names = {"x", "x'"};
  e.original.rhs = [=](double t, const double* y, double* dy) {
    dy[0] = y[1];
    dy[1] = F1 * std::cos(w1 * t) + F2 * std::cos(w2 * t) - c * y[1] - k * y[0] -
            a * y[0] * y[0] * y[0];
  };
  e.original.state = [](const HarmonicSolution& h, double t) {
    return Eigen::Vector2d(h.Value(0, t), h.Value(1, t)).eval();
  };
  return e;
}

}  // namespace

const std::vector<Example>& AllExamples() {
  static const std::vector<Example> examples = {
      {"duffing", "Forced Duffing oscillator", "x'' + c x' + k x + a x^3 = F cos(w t)",
       {{"c", 0.1, "damping"}, {"k", 1.0, "linear stiffness"}, {"a", 1.0, "cubic stiffness"},
        {"F", 1.0, "forcing amplitude"}, {"w", 1.5, "forcing frequency", 0}},
       Duffing},
      {"vanderpol", "Free Van der Pol oscillator (limit cycle)", "x'' - eps (1 - x^2) x' + x = 0",
       {{"eps", 1.0, "nonlinear damping (relaxation for eps >> 1)"}},
       VanDerPol},
      {"pendulum", "Nonlinear pendulum released from rest", "theta'' + sin(theta) = 0",
       {{"theta0", 1.5, "initial angle theta(0), 0 < |theta0| < pi"}},
       Pendulum},
      {"relativistic", "Relativistic harmonic oscillator", "x'' + (1 - x'^2)^(3/2) x = 0",
       {{"beta", 0.85, "initial velocity x'(0) as a fraction of c, x(0) = 0"}},
       Relativistic},
      {"rayleigh-plesset", "Forced Rayleigh-Plesset bubble",
       "R R'' = -3/2 R'^2 - A R'/R - B/R + C/R^3 + D - E cos(w t)",
       {{"A", 0.1, "viscous term"}, {"B", 1.0, "surface tension term"},
        {"C", 2.0, "gas pressure term"}, {"D", -1.0, "ambient pressure term"},
        {"E", 0.2, "acoustic forcing amplitude"}, {"w", 2.0, "forcing frequency", 0}},
       RayleighPlesset},
      {"asym-pendulum", "Asymmetric spherical pendulum (quasi-periodic, two unknown bases)",
       "x'' + (1-k) x = -(1-k)(x x'^2 + x y'^2 + x y y'' + x^2 x''), "
       "y'' + y = -(y y'^2 + y x'^2 + x y x'' + y^2 y'')",
       {{"kappa", 0.01, "asymmetry"}, {"x0", 0.1, "x(0), x'(0) = 0"}, {"y0", 0.2, "y(0), y'(0) = 0"}},
       AsymmetricPendulum},
      {"forced-vanderpol", "Forced Van der Pol oscillator (quasi-periodic when not locked)",
       "x'' - eps (1 - x^2) x' + x = F cos(w t)",
       {{"eps", 0.2, "nonlinear damping"}, {"F", 0.5, "forcing amplitude"}, {"w", 2.3, "forcing frequency"}},
       ForcedVanDerPol},
      {"duffing-2tone", "Duffing oscillator forced by two tones (two known bases)",
       "x'' + c x' + k x + a x^3 = F1 cos(w1 t) + F2 cos(w2 t)",
       {{"c", 0.1, "damping"}, {"k", 2.0, "linear stiffness"}, {"a", 1.0, "cubic stiffness"},
        {"F1", 0.5, "first tone's amplitude"}, {"F2", 0.5, "second tone's amplitude"},
        {"w1", 0.7, "first tone's frequency", 0}, {"w2", 1.1, "second tone's frequency", 1}},
       DuffingTwoTone},
  };
  return examples;
}

const Example* FindExample(const std::string& name) {
  for (const auto& e : AllExamples())
    if (e.name == name) return &e;
  return nullptr;
}

ExampleSetup BuildExample(const std::string& name, const std::map<std::string, double>& overrides) {
  const Example* example = FindExample(name);
  if (!example) {
    std::string known;
    for (const auto& e : AllExamples()) known += (known.empty() ? "" : ", ") + e.name;
    throw std::invalid_argument("unknown example '" + name + "' (known: " + known + ")");
  }
  Values values;
  for (const auto& p : example->parameters) values[p.name] = p.value;
  for (const auto& [k, v] : overrides) {
    if (!values.count(k)) {
      std::string known;
      for (const auto& p : example->parameters) known += (known.empty() ? "" : ", ") + p.name;
      throw std::invalid_argument("example '" + name + "' has no parameter '" + k +
                                  "' (parameters: " + known + ")");
    }
    if (!std::isfinite(v))
      throw std::invalid_argument("parameter '" + k + "' must be finite");
    values[k] = v;
  }
  ExampleSetup e = example->build(values);
  // The hand-written recasts keep the state in their first variables; the
  // auxiliaries' definitions are original.variables on it.
  if (e.original.variables && !e.problem.definitions) {
    const int dimension = e.original.dimension();
    e.problem.definitions.evaluate = [dimension, f = e.original.variables](
                                         const std::vector<double>&, const std::vector<Eigen::VectorXd>& z) {
      return f(z[0].head(dimension));
    };
  }
  return e;
}

}  // namespace rmhb::examples
