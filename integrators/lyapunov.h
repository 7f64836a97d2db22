#ifndef RMHB_INTEGRATORS_LYAPUNOV_H_
#define RMHB_INTEGRATORS_LYAPUNOV_H_

// Lyapunov exponents of a trajectory of the ORIGINAL equations y' = f(t, y):
// the variational equations Phi' = J(t, y(t)) Phi (integrators/
// variational.h) integrated with CVODE over `segments` segments of length
// `segment`, Phi re-orthonormalised by a QR factorisation after each (the
// standard method of Benettin et al. 1980 and Shimada & Nagashima 1979:
// without it every column aligns with the most expanding direction and the
// others are lost to round-off). The exponents are the time averages of
// log|R_ii|. They converge like 1/T: the report gives the largest change
// of any exponent between the first half of the span and the whole, the
// number a verdict must be judged against (rmhb/pipeline/torus.h). On a
// quasi-periodic torus the trajectory from a point of the torus stays on it
// and covers it densely, so one trajectory gives the torus' exponents.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"
#include "integrators/variational.h"

namespace rmhb::integrators {

struct LyapunovOptions {
  IntegratorOptions integrator;  // Adams, rtol 1e-12 by default; 1e-9 is plenty for exponents
  JacobianFunction jacobian;     // empty: central differences
  double segment = 1;            // time between re-orthonormalisations, > 0
  int segments = 1000;           // >= 2
  std::string IsValid() const;   // empty when valid
};

struct LyapunovReport {
  bool ok = false;
  std::string message;             // the integration's failure, if any
  std::vector<double> exponents;   // by decreasing value
  // max_i |lambda_i(T) - lambda_i(T / 2)|: the exponents' convergence.
  double spread = 0;
  double time = 0;                 // the span T integrated
  // The trajectory y at the end of each segment (one row each, at t0 +
  // (i + 1) segment): whether it stayed where it started, e.g. on a torus.
  Eigen::MatrixXd segment_states;
  long steps = 0;
  double seconds = 0;
  std::string BriefReport() const;
};

// Throws std::invalid_argument for misuse (invalid options, y0 of the
// wrong size or not finite); a failed integration is ok = false.
LyapunovReport LyapunovExponents(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                 const LyapunovOptions& options);

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_LYAPUNOV_H_
