#ifndef RMHB_TESTS_MODEL_RK4_H_
#define RMHB_TESTS_MODEL_RK4_H_

// Classical fixed-step Runge-Kutta 4 on an OriginalSystem, an independent
// reference for the harmonic balance solutions of forced and quasi-periodic
// models (error ~ h^4: h = 1e-3 gives ~1e-12 over a few periods).

#include <vector>

#include "rmhb/model/original_system.h"

namespace rmhb::testing {

inline std::vector<double> IntegrateRk4(const model::OriginalSystem& system, std::vector<double> y,
                                        double t0, double t1, int steps) {
  const int n = system.dimension;
  std::vector<double> k1(n), k2(n), k3(n), k4(n), tmp(n);
  const double h = (t1 - t0) / steps;
  double t = t0;
  for (int s = 0; s < steps; ++s) {
    system.rhs(t, y.data(), k1.data());
    for (int i = 0; i < n; ++i) tmp[i] = y[i] + 0.5 * h * k1[i];
    system.rhs(t + 0.5 * h, tmp.data(), k2.data());
    for (int i = 0; i < n; ++i) tmp[i] = y[i] + 0.5 * h * k2[i];
    system.rhs(t + 0.5 * h, tmp.data(), k3.data());
    for (int i = 0; i < n; ++i) tmp[i] = y[i] + h * k3[i];
    system.rhs(t + h, tmp.data(), k4.data());
    for (int i = 0; i < n; ++i) y[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    t = t0 + (s + 1) * h;
  }
  return y;
}

}  // namespace rmhb::testing

#endif  // RMHB_TESTS_MODEL_RK4_H_
