#include "integrators/event_detection.h"

#include <cvode/cvode.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "integrators/detail/cvode_session.h"
#include "integrators/detail/validation.h"

namespace rmhb::integrators {
namespace {

constexpr double kEpsilon = std::numeric_limits<double>::epsilon();

// g along CVODE's interpolant of the last step. False if t is outside the
// step or g misbehaves; the caller then keeps CVODE's own root.
bool EventAlongStep(detail::CvodeSession& session, const EventFunction& g, double t,
                    Eigen::VectorXd* y, double* value) {
  if (!session.Interpolate(t, y)) return false;
  try {
    *value = g(t, y->data());
  } catch (...) {
    return false;
  }
  return std::isfinite(*value);
}

// CVODE stops bisecting once the bracket is narrower than
// ttol = 100 u (|t| + |h|), which at t ~ 10 is ~2e-13: too coarse for
// period measurements at 1e-12 relative with margin. The function it
// bracketed, g on the interpolant, is smooth, so a secant iteration on the
// same function reaches a few ulps in 2-3 evaluations.
double RefineCrossing(detail::CvodeSession& session, const EventFunction& g, double t_cvode) {
  double step_begin = 0.0, step_end = 0.0;
  session.LastStepInterval(&step_begin, &step_end);
  const double width = step_end - step_begin;
  if (!(width > 0)) return t_cvode;
  const double cvode_tolerance = 100 * kEpsilon * (std::fabs(step_end) + width);

  Eigen::VectorXd y;
  double t1 = t_cvode, g1 = 0.0;
  if (!EventAlongStep(session, g, t1, &y, &g1)) return t_cvode;
  if (g1 == 0.0) return t1;
  // The second point is far enough for the secant slope to be free of
  // round-off, close enough for curvature not to matter.
  const double offset = std::max(1e-6 * width, cvode_tolerance);
  double t0 = t1 - offset >= step_begin ? t1 - offset : t1 + offset, g0 = 0.0;
  if (!EventAlongStep(session, g, t0, &y, &g0)) return t_cvode;

  for (int iteration = 0; iteration < 8; ++iteration) {
    if (g1 == g0) break;
    const double t2 = t1 - g1 * (t1 - t0) / (g1 - g0);
    // CVODE's bracket contains the root; leaving its neighbourhood means the
    // secant met another zero or a flat spot, and CVODE's answer is safer.
    if (!(std::fabs(t2 - t_cvode) <= 10 * cvode_tolerance) || t2 < step_begin || t2 > step_end) {
      return t_cvode;
    }
    t0 = t1;
    g0 = g1;
    t1 = t2;
    if (!EventAlongStep(session, g, t1, &y, &g1)) return t_cvode;
    if (g1 == 0.0 || std::fabs(t1 - t0) <= 2 * kEpsilon * std::fabs(t1)) break;
  }
  return t1;
}

}  // namespace

std::vector<double> FindCrossings(const OdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                  double t_end, const EventFunction& g, int direction,
                                  const IntegratorOptions& options, IntegrationResult* info) {
  constexpr const char* kCaller = "FindCrossings";
  detail::ValidateSystem(system, kCaller);
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  detail::ValidateOptions(options, /*for_ida=*/false, kCaller);
  if (!g) throw std::invalid_argument(std::string(kCaller) + ": event function is empty");
  if (!(std::isfinite(t_end) && t_end > t0)) {
    throw std::invalid_argument(std::string(kCaller) + ": t_end must be finite and > t0");
  }
  if (direction < -1 || direction > 1) {
    throw std::invalid_argument(std::string(kCaller) + ": direction must be -1, 0 or +1, got " +
                                std::to_string(direction));
  }

  const auto start = std::chrono::steady_clock::now();
  std::vector<double> times;
  std::vector<Eigen::VectorXd> states;

  detail::CvodeSession session(system, y0, t0, options);
  if (session.ok() && session.SetEventFunction(&g, direction)) {
    double t_reached = t0;
    while (session.Advance(t_end, &t_reached) == CV_ROOT_RETURN) {
      const double t_root = RefineCrossing(session, g, t_reached);
      Eigen::VectorXd y;
      if (!session.Interpolate(t_root, &y)) {
        y = Eigen::Map<const Eigen::VectorXd>(session.state(), system.dimension);
      }
      times.push_back(t_root);
      states.push_back(std::move(y));
      if (t_reached >= t_end) break;
    }
  }

  if (info != nullptr) {
    IntegrationResult& result = *info;
    result = IntegrationResult();
    result.solver = session.solver_name();
    result.status = session.ok() ? IntegrationStatus::kSuccess : IntegrationStatus::kFailure;
    result.message = session.failure();
    result.trajectory.times = times;
    result.trajectory.states.resize(static_cast<Eigen::Index>(times.size()), system.dimension);
    for (std::size_t k = 0; k < states.size(); ++k) {
      result.trajectory.states.row(static_cast<Eigen::Index>(k)) = states[k].transpose();
    }
    result.steps = session.steps();
    result.rhs_evaluations = session.rhs_evaluations();
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  return times;
}

double LimitCyclePeriod(const OdeSystem& system, const Eigen::VectorXd& y0, double t_end,
                        const EventFunction& g, int direction, int transient_crossings,
                        const IntegratorOptions& options, IntegrationResult* info) {
  IntegrationResult local;
  IntegrationResult* result = info ? info : &local;
  const std::vector<double> crossings =
      FindCrossings(system, y0, 0.0, t_end, g, direction, options, result);
  const int usable = static_cast<int>(crossings.size()) - std::max(0, transient_crossings);
  if (!result->ok() || usable < 2) return std::numeric_limits<double>::quiet_NaN();
  return (crossings.back() - crossings[crossings.size() - usable]) / (usable - 1);
}

std::vector<double> SectionReturns(const OdeSystem& system, const Eigen::VectorXd& y0, double t_end,
                                   const IntegratorOptions& options, IntegrationResult* info) {
  detail::ValidateSystem(system, "SectionReturns");
  detail::ValidateVector(y0, system.dimension, "y0", "SectionReturns");
  Eigen::VectorXd f0(y0.size());
  system.rhs(0, y0.data(), f0.data());
  if (!f0.allFinite() || f0.norm() == 0) return {};
  const auto section = [&](double, const double* y) {
    return (Eigen::Map<const Eigen::VectorXd>(y, y0.size()) - y0).dot(f0);
  };
  return FindCrossings(system, y0, 0, t_end, section, +1, options, info);
}

}  // namespace rmhb::integrators
