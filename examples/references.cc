#include "examples/references.h"

#include <cmath>
#include <stdexcept>

#include "examples/example_system.h"
#include "integrators/event_detection.h"
#include "integrators/integrator_options.h"

namespace rmhb::examples {

double EllipticK(double m) {
  if (!(m >= 0 && m < 1)) throw std::invalid_argument("EllipticK: m must be in [0, 1)");
  double a = 1.0, b = std::sqrt(1.0 - m);
  for (int i = 0; i < 60 && std::abs(a - b) > 1e-17 * a; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return M_PI / (a + b);
}

double PendulumFrequency(double theta0) {
  const double m = std::pow(std::sin(0.5 * theta0), 2);
  return M_PI / (2.0 * EllipticK(m));
}

double PendulumCoefficient(double theta0, int n) {
  if (n % 2 == 0) return 0.0;
  const double m = std::pow(std::sin(0.5 * theta0), 2);
  const double q = std::exp(-M_PI * EllipticK(1.0 - m) / EllipticK(m));
  const int j = (n - 1) / 2;
  const double sign = j % 2 ? -1.0 : 1.0;
  return 8.0 * sign * std::pow(q, j + 0.5) / (n * (1.0 + std::pow(q, n)));
}

double PendulumAngle(double theta0, double t) {
  const double w = PendulumFrequency(theta0);
  double theta = 0;
  for (int n = 1; n < 400; n += 2) {
    const double a = PendulumCoefficient(theta0, n);
    theta += a * std::cos(n * w * t);
    if (std::abs(a) < 1e-18 * std::abs(theta0)) break;
  }
  return theta;
}

double RelativisticAmplitude(double beta) {
  if (!(std::abs(beta) < 1)) throw std::invalid_argument("relativistic: |beta| must be < 1");
  const double gamma0 = 1.0 / std::sqrt(1.0 - beta * beta);
  return std::sqrt(2.0 * (gamma0 - 1.0));
}

double RelativisticPeriod(double beta) {
  const double A = RelativisticAmplitude(beta);
  auto f = [A](double phi) {
    const double c2 = std::pow(std::cos(phi), 2);
    return (1.0 + 0.5 * A * A * c2) / std::sqrt(1.0 + 0.25 * A * A * c2);
  };
  // The integrand is even and pi-periodic: the trapezoid rule over a full
  // period is spectrally accurate; T = 4 * (1/2) * int_0^pi f = 2 int_0^pi f.
  // Stop at a change of a few ulps (a tighter test is never met and only
  // piles up rounding); Kahan summation keeps the sum itself exact-ish.
  double previous = 0;
  for (int n = 16; n <= (1 << 16); n *= 2) {
    double sum = 0, carry = 0;
    for (int i = 0; i < n; ++i) {
      const double y = f(M_PI * i / n) - carry;
      const double t = sum + y;
      carry = (t - sum) - y;
      sum = t;
    }
    const double T = 2.0 * M_PI * sum / n;
    if (std::abs(T - previous) <= 4e-16 * T) return T;
    previous = T;
  }
  return previous;
}

double VanDerPolPeriodByCvode(double eps) {
  const ExampleSetup e = BuildExample("vanderpol", {{"eps", eps}});
  integrators::OdeSystem ode{2, e.original.rhs};
  integrators::IntegratorOptions io;
  io.method = integrators::IntegratorOptions::Method::kBdf;
  io.relative_tolerance = integrators::kTightestRelativeTolerance;
  io.absolute_tolerance = 1e-17;
  // x' crosses zero downwards only at the maxima of x: one per period.
  return integrators::LimitCyclePeriod(ode, Eigen::Vector2d(2.0, 0.0),
                                       12 * 2 * M_PI / e.guess.frequencies()[0],
                                       [](double, const double* y) { return y[1]; }, -1, 2, io);
}

}  // namespace rmhb::examples
