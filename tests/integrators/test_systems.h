// Small problems with known solutions shared by the integrator tests.

#ifndef RMHB_TESTS_INTEGRATORS_TEST_SYSTEMS_H_
#define RMHB_TESTS_INTEGRATORS_TEST_SYSTEMS_H_

#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "integrators/ode_system.h"

namespace rmhb::integrators::testing {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
inline constexpr double kPi = 3.14159265358979323846;

inline Eigen::VectorXd Vec(std::initializer_list<double> values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  Eigen::Index i = 0;
  for (double x : values) v[i++] = x;
  return v;
}

// n equally spaced times from start to stop.
inline std::vector<double> Grid(double start, double stop, int n) {
  std::vector<double> times(n);
  for (int k = 0; k < n; ++k) times[k] = start + (stop - start) * k / (n - 1);
  return times;
}

// For RecordProperty: std::to_string prints 1e-12 as "0.000000".
inline std::string Sci(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3e", x);
  return buffer;
}

// theta'' = -sin(theta) from theta0 = 1.5 at rest has period
// 4 K(sin(0.75)); value from mpmath at 40 digits.
inline constexpr double kPendulumTheta0 = 1.5;
inline constexpr double kPendulumPeriod = 7.30086494213225287471815272861;

inline OdeSystem Pendulum() {
  OdeSystem system;
  system.dimension = 2;
  system.rhs = [](double, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = -std::sin(y[0]);
  };
  return system;
}

// x'' + x = 0 as (x, x'); from (1, 0) the solution is (cos t, -sin t).
inline OdeSystem HarmonicOscillator() {
  OdeSystem system;
  system.dimension = 2;
  system.rhs = [](double, const double* y, double* ydot) {
    ydot[0] = y[1];
    ydot[1] = -y[0];
  };
  return system;
}

}  // namespace rmhb::integrators::testing

#endif  // RMHB_TESTS_INTEGRATORS_TEST_SYSTEMS_H_
