#ifndef RMHB_INTEGRATORS_FLOQUET_H_
#define RMHB_INTEGRATORS_FLOQUET_H_

// Floquet multipliers of a periodic orbit of the ORIGINAL equations: the
// eigenvalues of the monodromy matrix Phi(T), integrated with CVODE over one
// period together with the variational equations Phi' = J(t, y(t)) Phi,
// Phi(0) = I. Independent of harmonic balance: it needs only the right-hand
// side, a point on the orbit and the period, which is what makes it a check
// of Hill's method (rmhb/hill_stability.h).
//
// The Jacobian J is the caller's when given, otherwise central differences
// of the right-hand side with steps cbrt(u) (1 + |y_i|): truncation error
// ~u^(2/3) ~ 4e-11 relative, well below the multipliers' other errors at
// the default tolerance.

#include <complex>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"

namespace rmhb::integrators {

struct FloquetOptions {
  IntegratorOptions integrator;  // Adams, rtol 1e-12, atol 1e-14 by default
  // Row-major n x n dJ = df/dy at (t, y); empty: central differences.
  std::function<void(double t, const double* y, double* jacobian)> jacobian;
  // An autonomous orbit always has a multiplier 1 (the phase shift along the
  // orbit); the one closest to 1 is then left out of the verdict.
  bool autonomous = false;
  // |mu| within margin of 1 is not decidable from a tolerance-limited
  // integration: not stable.
  double margin = 1e-8;
};

struct FloquetReport {
  bool ok = false;       // the integration succeeded
  std::string message;   // SUNDIALS' failure, if any
  Eigen::MatrixXd monodromy;
  // Eigenvalues of the monodromy matrix by decreasing modulus.
  std::vector<std::complex<double>> multipliers;
  int trivial = -1;      // index of the trivial multiplier (autonomous), or -1
  double max_modulus = 0;  // over the non-trivial multipliers
  bool stable = false;     // every non-trivial |mu| < 1 - margin
  // max |y(T) - y(0)|: how closely the start lies on a periodic orbit. A
  // harmonic balance solution that does not solve the original equations
  // (aliased, non-physical) shows here.
  double closure_error = 0;
  double seconds = 0;
  long steps = 0;

  std::string BriefReport() const;
};

// Throws std::invalid_argument for misuse (empty rhs, y0 of the wrong size,
// non-finite values, period <= 0); integration failures are ok = false.
FloquetReport FloquetMultipliers(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                 double period, const FloquetOptions& options = {});

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_FLOQUET_H_
