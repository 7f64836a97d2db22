#include "rmhb/pipeline/monodromy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "integrators/dae_floquet.h"
#include "integrators/floquet.h"
#include "rmhb/harmonic_monodromy.h"

namespace rmhb {
namespace {

// Models (or problems) by parameter value, the most recent first (a
// handful: the corrector's value and its finite-difference neighbour, the
// point's).
template <typename T>
class ValueCache {
 public:
  explicit ValueCache(std::function<T(double)> make) : make_(std::move(make)) {}
  std::shared_ptr<const T> At(double value) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [v, m] : values_)
      if (v == value) return m;
    auto made = std::make_shared<const T>(make_(value));
    values_.emplace_front(value, made);
    if (values_.size() > 4) values_.pop_back();
    return made;
  }

 private:
  std::function<T(double)> make_;
  std::deque<std::pair<double, std::shared_ptr<const T>>> values_;
  std::mutex mutex_;
};
using ModelCache = ValueCache<Model>;

// d/dt of the original state along the solution at t = 0.
Eigen::VectorXd Flow(const Model& model, const HarmonicSolution& solution) {
  const double h = 1e-5 * 2 * M_PI / solution.frequencies()[0];
  return (model.state(solution, h) - model.state(solution, -h)) / (2 * h);
}

// A piecewise-smooth model: the variational equations integrated event by
// event (integrators/switched_integration.h, METHOD.md s.15).
MonodromyResult SwitchedModelMonodromy(const Model& model, const HarmonicSolution& solution,
                                       const std::vector<double>& bases, const Eigen::VectorXd& y0,
                                       const integrators::FloquetOptions& floquet) {
  MonodromyResult result;
  const auto start = std::chrono::steady_clock::now();
  const double T = 2 * M_PI / solution.frequencies()[0];
  const Eigen::MatrixXd M =
      integrators::SwitchedMonodromy(model.original_switched(bases), y0, T, floquet.integrator, &result.message);
  result.integrator = std::string(OriginalIntegrator(model)) + ", switches located";
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (M.size() == 0) return result;
  result.ok = true;
  const Eigen::VectorXd flow = Flow(model, solution);
  if (floquet.autonomous && flow.norm() > 0) {
    DeflateTrivialMultiplier(M, flow, &result.multipliers, &result.trivial);
    return result;
  }
  const Eigen::VectorXcd mu = Eigen::EigenSolver<Eigen::MatrixXd>(M, false).eigenvalues();
  result.multipliers.assign(mu.data(), mu.data() + mu.size());
  std::sort(result.multipliers.begin(), result.multipliers.end(),
            [](const auto& a, const auto& b) { return std::abs(a) > std::abs(b); });
  return result;
}

}  // namespace

std::string ModelMonodromyOptions::IsValid() const {
  if (!(relative_tolerance > 0) || !(absolute_tolerance > 0) || !std::isfinite(relative_tolerance) ||
      !std::isfinite(absolute_tolerance))
    return "the monodromy's tolerances must be finite and > 0";
  return "";
}

MonodromyResult ModelMonodromy(const Model& model, const HarmonicSolution& solution, int period_multiple,
                               const ModelMonodromyOptions& options) {
  if (const std::string why = options.IsValid(); !why.empty()) throw std::invalid_argument(why);
  if (solution.frequencies().size() != 1)
    throw std::invalid_argument("monodromy: a quasi-periodic solution has no period");
  if (period_multiple < 1) throw std::invalid_argument("monodromy: period_multiple must be >= 1");
  MonodromyResult result;
  if (!model.original && !model.original_dae) {
    result.message = "no original equations: " + model.original_error;
    return result;
  }
  const double w = solution.frequencies()[0];
  const std::vector<double> bases(model.problem.frequencies.size(), w * period_multiple);
  integrators::FloquetOptions floquet;
  floquet.autonomous = model.problem.num_unknown_frequencies() > 0;
  floquet.integrator.relative_tolerance = options.relative_tolerance;
  floquet.integrator.absolute_tolerance = options.absolute_tolerance;
  if (model.stiff) floquet.integrator.method = integrators::IntegratorOptions::Method::kBdf;
  const Eigen::VectorXd y0 = model.state(solution, 0.0);
  if (model.original_switched) return SwitchedModelMonodromy(model, solution, bases, y0, floquet);
  const integrators::FloquetReport r =
      model.original_dae ? integrators::DaeFloquetMultipliers(model.original_dae(bases), y0, 0.0, 2 * M_PI / w, floquet)
                         : integrators::FloquetMultipliers(model.original(bases), y0, 0.0, 2 * M_PI / w, floquet);
  result.ok = r.ok;
  result.message = r.message;
  result.multipliers = r.multipliers;
  result.trivial = r.trivial;
  if (r.ok && floquet.autonomous) {
    Eigen::VectorXd flow = Flow(model, solution);
    if (model.original_dae) {  // the monodromy acts on the differential components
      const std::vector<bool> differential = model.original_dae(bases).differential;
      std::vector<double> kept;
      for (int i = 0; i < flow.size(); ++i)
        if (differential.empty() || differential[i]) kept.push_back(flow(i));
      flow = Eigen::Map<const Eigen::VectorXd>(kept.data(), static_cast<long>(kept.size()));
    }
    if (flow.size() == r.monodromy.rows() && flow.norm() > 0)
      DeflateTrivialMultiplier(r.monodromy, flow, &result.multipliers, &result.trivial);
  }
  result.integrator = OriginalIntegrator(model);
  result.seconds = r.seconds;
  return result;
}

ContinuationProblem ModelContinuationProblem(std::function<Model(double)> model_at, std::string parameter,
                                             double start, double end, const ModelMonodromyOptions& options) {
  if (const std::string why = options.IsValid(); !why.empty()) throw std::invalid_argument(why);
  auto cache = std::make_shared<ModelCache>(std::move(model_at));
  ContinuationProblem problem;
  problem.parameter = std::move(parameter);
  problem.start = start;
  problem.end = end;
  problem.build = [cache](double value) { return cache->At(value)->problem; };
  problem.monodromy = [cache, options](double value, const HarmonicSolution& solution, int period_multiple) {
    return ModelMonodromy(*cache->At(value), solution, period_multiple, options);
  };
  return problem;
}

ContinuationProblem ModelContinuationProblem(const Model& model, const std::string& parameter, double start,
                                             double end, const ModelMonodromyOptions& options) {
  auto base = std::make_shared<const Model>(model);
  ContinuationProblem problem = ModelContinuationProblem(
      [base, parameter](double value) { return WithParameters(*base, {{parameter, value}}); }, parameter, start, end,
      options);
  // The problem alone where the model can rebuild it alone (the monodromy
  // keeps whole models).
  if (model.reload_problem) {
    auto problems = std::make_shared<ValueCache<HarmonicBalanceProblem>>(
        [base, parameter](double value) { return ProblemWithParameters(*base, {{parameter, value}}); });
    problem.build = [problems](double value) { return *problems->At(value); };
  }
  const auto bound = model.frequency_parameters.find(parameter);
  if (bound == model.frequency_parameters.end() || !model.frequency_settings.empty()) return problem;
  HarmonicBalanceProblem first;
  try {
    first = problem.build(start);
  } catch (const std::exception&) {
    return problem;  // the trace reports it
  }
  problem.build = [first = std::move(first), base = bound->second, full = problem.build](double value) {
    if (!(value > 0) || !std::isfinite(value)) return full(value);  // the model's refusal, as it words it
    HarmonicBalanceProblem p = first;
    p.frequencies[base] = value;
    return p;
  };
  problem.only_frequencies_change = true;
  return problem;
}

integrators::ValidationReport ValidateTorus(const Model& model, const HarmonicSolution& torus, double t_end,
                                            int samples) {
  if (!model.original && !model.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + model.original_error);
  if (torus.frequencies().size() != model.problem.frequencies.size() + 1)
    throw std::invalid_argument("ValidateTorus: the torus must have one base more than the model");
  const std::vector<double> w(torus.frequencies().begin(), torus.frequencies().end() - 1);
  auto claimed = [&](double t) { return model.state(torus, t); };
  return model.original_dae ? integrators::ValidateDaeTrajectory(model.original_dae(w), claimed, t_end, samples)
                            : integrators::ValidateTrajectory(model.original(w), claimed, t_end, model.stiff, samples);
}

}  // namespace rmhb
