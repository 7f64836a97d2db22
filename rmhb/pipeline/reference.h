#ifndef RMHB_PIPELINE_REFERENCE_H_
#define RMHB_PIPELINE_REFERENCE_H_

// An exact answer a model may carry (the bundled examples do: elliptic
// integrals for the pendulum, an energy quadrature for the relativistic
// oscillator), and a solution's errors against it, measured one way for
// every study (solve, continuation, convergence).

#include <functional>
#include <limits>
#include <string>

#include "rmhb/harmonic_solution.h"

namespace rmhb {

struct ExactReference {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  double frequency = kNone;  // exact angular frequency
  double amplitude = kNone;  // exact max |z| of variable `amplitude_variable`
  std::string amplitude_variable;
  std::function<double(double t)> solution;  // exact first variable, if known
  std::string source;                        // where the numbers come from
  bool has_frequency() const { return frequency == frequency; }
  bool has_amplitude() const { return amplitude == amplitude; }
  bool empty() const { return !has_frequency() && !has_amplitude() && !solution; }
};

// Signed errors (solution - exact); NaN where the reference has no such number.
struct ReferenceErrors {
  double frequency = ExactReference::kNone;  // w_1 - exact
  double amplitude = ExactReference::kNone;  // amplitude - exact
  double max_error = ExactReference::kNone;  // max over one period of |z_0(t) - exact|, 2001 samples
};
ReferenceErrors ErrorsAgainst(const ExactReference& reference, const HarmonicSolution& solution);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_REFERENCE_H_
