#ifndef RMHB_FREQUENCY_ID_FREQUENCY_REFINEMENT_H_
#define RMHB_FREQUENCY_ID_FREQUENCY_REFINEMENT_H_

#include <string>

#include <Eigen/Core>

#include "frequency_id/sample_grid.h"

namespace rmhb::frequency_id {

// Laskar's NAFF objective for a multichannel record and its first two
// derivatives in omega:
//
//   phi_c(omega) = (1/sum w) sum_n w_n x_nc e^{-i omega tau_n},
//   S(omega)     = sum_c |phi_c(omega)|^2,
//
// i.e. the trapezoid rule for (1/T) int x(t) W(t) e^{-i omega t} dt, which is
// spectrally accurate because the window and its derivatives vanish at both
// ends. It is evaluated directly on the samples at any omega, not read off
// FFT bins, so a maximiser is limited by round-off only.
struct LinePower {
  double value = 0.0;   // S
  double first = 0.0;   // dS/domega
  double second = 0.0;  // d2S/domega2
};

// `windowed` holds w_n x_nc (grid.size rows, one column per channel) and
// `weight_sum` is sum_n w_n.
LinePower EvaluateLinePower(const SampleGrid& grid, const Eigen::MatrixXd& windowed,
                            double weight_sum, double omega);

// Gradient-based NLopt algorithms usable for the bracketed maximisation.
enum class RefinementAlgorithm { kMMA, kCCSAQ, kSLSQP, kLBFGS };
const char* ToString(RefinementAlgorithm algorithm);

struct RefinementOptions {
  RefinementAlgorithm algorithm = RefinementAlgorithm::kMMA;
  // NLopt only has to land in Newton's basin, so its budget is small.
  int max_optimizer_evaluations = 40;
  // NLopt's stopping tolerance on omega, in units of the bracket half-width.
  double optimizer_tolerance = 1e-4;
  // Newton on dS/domega = 0 converges quadratically; this is a safeguard.
  int max_newton_iterations = 20;
};

struct RefinedLine {
  double frequency = 0.0;
  double amplitude = 0.0;  // 2 sqrt(S) at the maximum: the line amplitude
  double power = 0.0;      // S at the maximum
  int evaluations = 0;     // of EvaluateLinePower, NLopt and Newton together
  int newton_iterations = 0;
  bool converged = false;  // Newton's step fell to round-off inside the bracket
  int nlopt_result = 0;    // nlopt_result code of the bracketed stage
};

// Maximises S(omega) over [lower, upper] (which must contain `start`, a
// spectrum peak): NLopt with the analytic derivative finds the maximum in the
// bracket, then Newton on dS/domega = 0 (safeguarded by bisection on the sign
// of dS/domega) polishes it to round-off, which no derivative-free search
// can do: S is flat to O(delta^2) at the peak, so comparing values resolves
// omega to sqrt(eps) only.
RefinedLine RefineLineFrequency(const SampleGrid& grid, const Eigen::MatrixXd& windowed,
                                double weight_sum, double lower, double upper, double start,
                                const RefinementOptions& options = RefinementOptions());

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_FREQUENCY_REFINEMENT_H_
