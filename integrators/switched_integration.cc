#include "integrators/switched_integration.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include <cvode/cvode.h>

#include "integrators/detail/cvode_session.h"
#include "integrators/detail/validation.h"
#include "integrators/variational.h"

namespace rmhb::integrators {
namespace {

// The first modes: the side of each argument at t0; an argument at zero
// takes the side it moves to (its change over a short explicit step, with
// the other switches on their sides).
std::vector<signed char> InitialModes(const SwitchedOdeSystem& system, const Eigen::VectorXd& y0, double t0) {
  const int n = system.num_switches;
  std::vector<signed char> modes(n, 1);
  Eigen::VectorXd ydot(system.dimension), arguments(n), ahead(n);
  system.rhs(t0, y0.data(), modes.data(), ydot.data(), arguments.data());
  for (int k = 0; k < n; ++k) modes[k] = arguments(k) < 0 ? -1 : 1;
  system.rhs(t0, y0.data(), modes.data(), ydot.data(), arguments.data());
  const double h = 1e-7 * (1 + std::abs(t0));
  const Eigen::VectorXd y1 = y0 + h * ydot;
  system.rhs(t0 + h, y1.data(), modes.data(), ydot.data(), ahead.data());
  for (int k = 0; k < n; ++k)
    if (arguments(k) == 0) modes[k] = ahead(k) < 0 ? -1 : 1;
  if (system.next_mode)
    for (int k = 0; k < n; ++k) modes[k] = static_cast<signed char>(system.next_mode(t0, y0.data(), k, 0, modes.data()));
  return modes;
}

}  // namespace

SwitchedIntegration IntegrateSwitched(const SwitchedOdeSystem& system, const Eigen::VectorXd& y0, double t0,
                                      const std::vector<double>& output_times, const IntegratorOptions& options,
                                      int max_events) {
  constexpr const char* kCaller = "IntegrateSwitched";
  if (!system.rhs || system.dimension <= 0 || system.num_switches < 0)
    throw std::invalid_argument(std::string(kCaller) + ": empty right-hand side or dimension <= 0");
  detail::ValidateVector(y0, system.dimension, "y0", kCaller);
  detail::ValidateInitialTime(t0, kCaller);
  detail::ValidateOutputTimes(output_times, t0, kCaller);
  detail::ValidateOptions(options, /*for_ida=*/false, kCaller);

  const auto start = std::chrono::steady_clock::now();
  SwitchedIntegration out;
  IntegrationResult& result = out.result;
  Trajectory& trajectory = result.trajectory;
  trajectory.states.resize(static_cast<Eigen::Index>(output_times.size()), system.dimension);
  std::vector<signed char> modes = InitialModes(system, y0, t0);
  OdeSystem frozen;
  frozen.dimension = system.dimension;
  frozen.rhs = [&](double t, const double* y, double* ydot) { system.rhs(t, y, modes.data(), ydot, nullptr); };
  std::vector<double> ydot(system.dimension);
  const MultiEventFunction arguments = [&](double t, const double* y, double* g) {
    system.rhs(t, y, modes.data(), ydot.data(), g);
  };

  Eigen::VectorXd y = y0;
  double t = t0;
  std::vector<int> found(system.num_switches);
  bool ok = true;
  std::string failure;
  std::size_t next = 0;
  while (ok && next < output_times.size()) {
    // One smooth segment: a fresh CVODE from (t, y) until a crossing.
    detail::CvodeSession session(frozen, y, t, options);
    result.solver = session.solver_name();
    ok = session.ok() && (system.num_switches == 0 || session.SetEventFunctions(system.num_switches, &arguments));
    bool crossed = false;
    while (ok && !crossed && next < output_times.size()) {
      const double t_out = output_times[next];
      if (t_out == t) {
        trajectory.states.row(static_cast<Eigen::Index>(next++)) = y.transpose();
        trajectory.times.push_back(t_out);
        continue;
      }
      double t_reached = t;
      const int flag = session.Advance(t_out, &t_reached);
      if (flag < 0) {
        ok = false;
        break;
      }
      y = Eigen::Map<const Eigen::VectorXd>(session.state(), system.dimension);
      t = t_reached;
      if (flag == CV_ROOT_RETURN) {
        session.RootsFound(found.data());
        const std::vector<signed char> before = modes;
        for (int k = 0; k < system.num_switches; ++k)
          if (found[k] != 0)
            modes[k] = static_cast<signed char>(system.next_mode ? system.next_mode(t, y.data(), k, found[k], before.data())
                                                                 : (found[k] > 0 ? 1 : -1));
        if (system.at_switch) system.at_switch(t, y.data(), before.data(), modes.data());
        crossed = true;
        if (++out.events > max_events) {
          ok = false;
          failure = "more than " + std::to_string(max_events) +
                    " switch crossings (chattering or sliding along a switching surface)";
        }
        if (t < t_out) continue;  // the output time itself is reached in the next segment
      }
      trajectory.states.row(static_cast<Eigen::Index>(next++)) = y.transpose();
      trajectory.times.push_back(t_out);
    }
    if (!session.ok()) failure = session.failure();
    result.steps += session.steps();
    result.rhs_evaluations += session.rhs_evaluations();
  }
  trajectory.states.conservativeResize(trajectory.size(), system.dimension);
  result.status = ok ? IntegrationStatus::kSuccess : IntegrationStatus::kFailure;
  result.message = failure;
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

namespace {

// Central differences (~cbrt(eps) steps) at (t, y) in `modes`: of the field,
// df/dy into *J (n x n), and of the switch arguments, dg/dy into *G (m x n),
// each when given. y is restored on return.
void CentralDifferences(const SwitchedOdeSystem& system, double t, Eigen::VectorXd* y, const signed char* modes,
                        Eigen::MatrixXd* J, Eigen::MatrixXd* G) {
  const int n = system.dimension, m = system.num_switches;
  thread_local Eigen::VectorXd fp, fm, gp, gm;
  fp.resize(n), fm.resize(n), gp.resize(m), gm.resize(m);
  if (J) J->resize(n, n);
  if (G) G->resize(m, n);
  for (int j = 0; j < n; ++j) {
    const double h = 6e-6 * (1 + std::abs((*y)(j)));
    const double saved = (*y)(j);
    (*y)(j) = saved + h;
    system.rhs(t, y->data(), modes, fp.data(), G ? gp.data() : nullptr);
    (*y)(j) = saved - h;
    system.rhs(t, y->data(), modes, fm.data(), G ? gm.data() : nullptr);
    (*y)(j) = saved;
    if (J) J->col(j) = (fp - fm) / (2 * h);
    if (G) G->col(j) = (gp - gm) / (2 * h);
  }
}

// The saltation matrix of the crossing at (t, y) from the modes `before` to
// `after` (SwitchedMonodromy): each switch that changed, in turn; a grazing
// crossing (grad g . f- + g_t ~ 0) has none (the identity is kept).
Eigen::MatrixXd Saltation(const SwitchedOdeSystem& system, double t, const Eigen::VectorXd& y,
                          const signed char* before, const signed char* after) {
  const int n = system.dimension, m = system.num_switches;
  Eigen::MatrixXd S = Eigen::MatrixXd::Identity(n, n), G;
  std::vector<signed char> modes(before, before + m);
  Eigen::VectorXd f_before(n), f_after(n), g(m), gp(m), gm(m), scratch(n), x = y;
  for (int k = 0; k < m; ++k) {
    if (before[k] == after[k]) continue;
    system.rhs(t, y.data(), modes.data(), f_before.data(), g.data());
    CentralDifferences(system, t, &x, modes.data(), nullptr, &G);
    const Eigen::VectorXd grad = G.row(k).transpose();
    const double ht = 6e-6 * (1 + std::abs(t));
    system.rhs(t + ht, y.data(), modes.data(), scratch.data(), gp.data());
    system.rhs(t - ht, y.data(), modes.data(), scratch.data(), gm.data());
    const double rate = grad.dot(f_before) + (gp(k) - gm(k)) / (2 * ht);
    modes[k] = after[k];
    system.rhs(t, y.data(), modes.data(), f_after.data(), nullptr);
    if (!(std::abs(rate) > 1e-12 * (1 + grad.norm() * f_before.norm()))) continue;
    S = (Eigen::MatrixXd::Identity(n, n) + (f_after - f_before) * grad.transpose() / rate) * S;
  }
  return S;
}

}  // namespace

Eigen::MatrixXd SwitchedMonodromy(const SwitchedOdeSystem& system, const Eigen::VectorXd& y0, double T,
                                  const IntegratorOptions& options, std::string* failure) {
  const int n = system.dimension;
  SwitchedOdeSystem augmented;
  augmented.dimension = n + n * n;
  augmented.num_switches = system.num_switches;
  augmented.next_mode = system.next_mode;
  augmented.rhs = [&system, n](double t, const double* z, const signed char* modes, double* zdot, double* arguments) {
    system.rhs(t, z, modes, zdot, arguments);
    thread_local Eigen::VectorXd y;
    thread_local Eigen::MatrixXd J;
    y = Eigen::Map<const Eigen::VectorXd>(z, n);
    CentralDifferences(system, t, &y, modes, &J, nullptr);
    Eigen::Map<Eigen::MatrixXd>(zdot + n, n, n) = J * Eigen::Map<const Eigen::MatrixXd>(z + n, n, n);
  };
  augmented.at_switch = [&system, n](double t, double* z, const signed char* before, const signed char* after) {
    Eigen::Map<Eigen::MatrixXd> phi(z + n, n, n);
    phi = Saltation(system, t, Eigen::Map<const Eigen::VectorXd>(z, n), before, after) * phi;
  };
  const Eigen::VectorXd z0 = VariationalStart(y0);
  const SwitchedIntegration r = IntegrateSwitched(augmented, z0, 0.0, {T}, options);
  if (!r.result.ok()) {
    if (failure) *failure = r.result.message;
    return {};
  }
  const Eigen::VectorXd zT = r.result.trajectory.states.row(0).transpose();
  return Eigen::Map<const Eigen::MatrixXd>(zT.data() + n, n, n);
}

ValidationReport ValidateSwitchedTrajectory(const SwitchedOdeSystem& system,
                                            const std::function<Eigen::VectorXd(double)>& claimed, double t_end,
                                            int samples) {
  if (!(t_end > 0) || !std::isfinite(t_end))
    throw std::invalid_argument("ValidateSwitchedTrajectory: t_end must be finite and > 0");
  if (samples < 2) throw std::invalid_argument("ValidateSwitchedTrajectory: need at least 2 samples");
  std::vector<double> times(samples);
  for (int i = 0; i < samples; ++i) times[i] = t_end * i / (samples - 1);
  IntegratorOptions options;
  options.relative_tolerance = 1e-13;
  options.absolute_tolerance = 1e-15;
  const auto start = std::chrono::steady_clock::now();
  const SwitchedIntegration r = IntegrateSwitched(system, claimed(0.0), 0.0, times, options);
  ValidationReport report;
  report.samples = samples;
  report.ok = r.result.ok();
  report.message = r.result.message;
  report.integrator = "CVODE Adams, rtol 1e-13, " + std::to_string(r.events) + " switch crossings located";
  if (!report.ok) {
    report.max_error = NAN;
  } else {
    for (int i = 0; i < samples; ++i) {
      const double e = (claimed(times[i]) - r.result.trajectory.states.row(i).transpose()).cwiseAbs().maxCoeff();
      if (e > report.max_error) report.max_error = e, report.error_time = times[i];
    }
  }
  report.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace rmhb::integrators
