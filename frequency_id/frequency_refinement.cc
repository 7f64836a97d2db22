#include "frequency_id/frequency_refinement.h"

#include <nlopt.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace rmhb::frequency_id {

LinePower EvaluateLinePower(const SampleGrid& grid, const Eigen::MatrixXd& windowed,
                            double weight_sum, double omega) {
  const int channels = static_cast<int>(windowed.cols());
  // Per channel: sum y e^{-i w tau}, sum y tau e^{-i w tau}, sum y tau^2 e^{-i w tau}
  // as (re, im) pairs. Partial sums are flushed once per phasor anchor block:
  // two-level summation keeps the rounding error of the long sums small.
  std::vector<double> block(6 * channels, 0.0);
  std::vector<double> total(6 * channels, 0.0);
  ForEachPhasor(grid, omega, [&](int n, double c, double s) {
    const double tau = grid.Tau(n);
    for (int ch = 0; ch < channels; ++ch) {
      const double y0 = windowed(n, ch);
      const double y1 = y0 * tau;
      const double y2 = y1 * tau;
      double* b = &block[6 * ch];
      b[0] += y0 * c;
      b[1] -= y0 * s;
      b[2] += y1 * c;
      b[3] -= y1 * s;
      b[4] += y2 * c;
      b[5] -= y2 * s;
    }
    if ((n + 1) % kPhasorAnchorStride == 0 || n + 1 == grid.size) {
      for (std::size_t i = 0; i < block.size(); ++i) {
        total[i] += block[i];
        block[i] = 0.0;
      }
    }
  });
  // phi = A0/W, phi' = -i A1/W, phi'' = -A2/W with A_k = sum y tau^k e^{-i w tau}.
  LinePower result;
  const double scale = 1.0 / (weight_sum * weight_sum);
  for (int ch = 0; ch < channels; ++ch) {
    const double* a = &total[6 * ch];
    const double a0r = a[0], a0i = a[1], a1r = a[2], a1i = a[3], a2r = a[4], a2i = a[5];
    result.value += (a0r * a0r + a0i * a0i) * scale;
    // 2 Re(conj(A0) (-i A1)) = 2 (a0r a1i - a0i a1r)
    result.first += 2.0 * (a0r * a1i - a0i * a1r) * scale;
    // 2 (|A1|^2 - Re(conj(A0) A2))
    result.second += 2.0 * (a1r * a1r + a1i * a1i - (a0r * a2r + a0i * a2i)) * scale;
  }
  return result;
}

const char* ToString(RefinementAlgorithm algorithm) {
  switch (algorithm) {
    case RefinementAlgorithm::kMMA: return "LD_MMA";
    case RefinementAlgorithm::kCCSAQ: return "LD_CCSAQ";
    case RefinementAlgorithm::kSLSQP: return "LD_SLSQP";
    case RefinementAlgorithm::kLBFGS: return "LD_LBFGS";
  }
  return "unknown";
}

namespace {

nlopt_algorithm ToNlopt(RefinementAlgorithm algorithm) {
  switch (algorithm) {
    case RefinementAlgorithm::kMMA: return NLOPT_LD_MMA;
    case RefinementAlgorithm::kCCSAQ: return NLOPT_LD_CCSAQ;
    case RefinementAlgorithm::kSLSQP: return NLOPT_LD_SLSQP;
    case RefinementAlgorithm::kLBFGS: return NLOPT_LD_LBFGS;
  }
  return NLOPT_LD_MMA;
}

// NLopt sees x = (omega - start) / half_width in about [-1, 1] and S scaled
// by S(start), so its tolerances are O(1) quantities whatever the units.
struct ScaledProblem {
  const SampleGrid* grid;
  const Eigen::MatrixXd* windowed;
  double weight_sum;
  double start;
  double half_width;
  double value_scale;
  int evaluations = 0;
  double best_omega;
  double best_value;
};

double ScaledObjective(unsigned /*n*/, const double* x, double* gradient, void* data) {
  auto* problem = static_cast<ScaledProblem*>(data);
  const double omega = problem->start + x[0] * problem->half_width;
  const LinePower power =
      EvaluateLinePower(*problem->grid, *problem->windowed, problem->weight_sum, omega);
  ++problem->evaluations;
  if (power.value > problem->best_value) {
    problem->best_value = power.value;
    problem->best_omega = omega;
  }
  if (gradient != nullptr) gradient[0] = power.first * problem->half_width * problem->value_scale;
  return power.value * problem->value_scale;
}

}  // namespace

RefinedLine RefineLineFrequency(const SampleGrid& grid, const Eigen::MatrixXd& windowed,
                                double weight_sum, double lower, double upper, double start,
                                const RefinementOptions& options) {
  RefinedLine line;
  start = std::clamp(start, lower, upper);
  const double half_width = std::max(upper - start, start - lower);
  const LinePower at_start = EvaluateLinePower(grid, windowed, weight_sum, start);
  ScaledProblem problem{&grid,  &windowed, weight_sum, start, half_width,
                        at_start.value > 0.0 ? 1.0 / at_start.value : 1.0,
                        1,      start,     at_start.value};

  // Stage 1: bracketed maximisation with the analytic derivative.
  nlopt_opt opt = nlopt_create(ToNlopt(options.algorithm), 1);
  if (opt != nullptr && half_width > 0.0) {
    double lb = (lower - start) / half_width;
    double ub = (upper - start) / half_width;
    nlopt_set_lower_bounds(opt, &lb);
    nlopt_set_upper_bounds(opt, &ub);
    nlopt_set_max_objective(opt, ScaledObjective, &problem);
    nlopt_set_xtol_abs1(opt, options.optimizer_tolerance);
    nlopt_set_maxeval(opt, options.max_optimizer_evaluations);
    double x = 0.0;
    double value = 0.0;
    line.nlopt_result = static_cast<int>(nlopt_optimize(opt, &x, &value));
  }
  if (opt != nullptr) nlopt_destroy(opt);
  // Whatever NLopt returned (it may stop on a round-off limit), continue
  // from the best point it evaluated.
  double omega = problem.best_omega;
  line.evaluations = problem.evaluations;

  // Stage 2: safeguarded Newton on dS/domega = 0. [lo, hi] shrinks to keep
  // the maximum bracketed by the sign of dS/domega.
  double lo = lower;
  double hi = upper;
  double previous_step = std::numeric_limits<double>::infinity();
  const double eps = std::numeric_limits<double>::epsilon();
  for (int iteration = 0; iteration < options.max_newton_iterations; ++iteration) {
    const LinePower power = EvaluateLinePower(grid, windowed, weight_sum, omega);
    ++line.evaluations;
    ++line.newton_iterations;
    if (power.first > 0.0) {
      lo = std::max(lo, omega);
    } else if (power.first < 0.0) {
      hi = std::min(hi, omega);
    } else {
      line.converged = true;
      break;
    }
    const double round_off = 4.0 * eps * std::max(std::abs(omega), half_width);
    bool newton_step = power.second < 0.0;
    // Test the Newton step before the bracket: at the root it rounds to
    // omega itself, which sits on the bracket's edge.
    if (newton_step && std::abs(power.first / power.second) <= round_off) {
      line.converged = true;
      break;
    }
    double next = newton_step ? omega - power.first / power.second : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) {
      next = 0.5 * (lo + hi);
      newton_step = false;
    }
    const double step = std::abs(next - omega);
    if (step <= round_off) {
      omega = next;
      line.converged = true;
      break;
    }
    // A step that no longer shrinks quadratically is round-off noise in
    // dS/domega: the current point is as good as it gets.
    if (newton_step && iteration >= 2 && step > 0.5 * previous_step) {
      line.converged = true;
      break;
    }
    omega = next;
    previous_step = newton_step ? step : std::numeric_limits<double>::infinity();
    if (hi - lo <= round_off) {
      line.converged = true;
      break;
    }
  }
  const LinePower final_power = EvaluateLinePower(grid, windowed, weight_sum, omega);
  ++line.evaluations;
  line.frequency = omega;
  line.power = final_power.value;
  line.amplitude = 2.0 * std::sqrt(std::max(0.0, final_power.value));
  return line;
}

}  // namespace rmhb::frequency_id
