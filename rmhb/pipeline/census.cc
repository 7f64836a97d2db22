#include "rmhb/pipeline/census.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "integrators/floquet.h"
#include "rmhb/pipeline/report.h"

namespace rmhb {
namespace {

using nlohmann::json;

json ClusterJson(const SolutionCluster& c) {
  json out = {{"class", ToString(c.solution_class)},
              {"count", c.count},
              {"share", JsonNumber(c.share)},
              {"amplitude", JsonNumber(c.amplitude)},
              {"reference_distance", JsonNumber(c.reference_distance)}};
  json stability = json::object();
  if (c.hill)
    stability["hill"] = {{"stable", c.hill->stable},
                         {"max_real_part", JsonNumber(c.hill->max_real_part)},
                         {"exponents", JsonComplex(c.hill->exponents)},
                         {"multipliers", JsonComplex(c.hill->multipliers)},
                         {"trivial", c.hill->trivial}};
  if (c.original) {
    stability["floquet"] = {{"ok", c.original->ok},
                            {"stable", c.original->stable},
                            {"multipliers", JsonComplex(c.original->multipliers)},
                            {"closure_error", JsonNumber(c.original->closure_error)},
                            {"message", c.original->message}};
    if (c.hill && c.original->ok) stability["agree"] = c.hill->stable == c.original->stable;
  }
  out["stability"] = stability;
  out["solution"] = SolutionJson(c.representative);
  return out;
}

json RuleJson(const RuleCensus& r) {
  json clusters = json::array();
  for (const auto& c : r.clusters) clusters.push_back(ClusterJson(c));
  return {{"method", ToString(r.rule)},
          {"samples", r.samples},
          {"alias_free_samples", r.alias_free_samples},
          {"alias_free", r.samples >= r.alias_free_samples},
          {"converged", r.converged},
          {"failed", r.failed},
          {"distinct_solutions", r.clusters.size()},
          {"non_physical_solutions", r.non_physical_clusters()},
          {"shares", {{"physical_stable", JsonNumber(r.share(SolutionClass::kPhysicalStable))},
                      {"physical_unstable", JsonNumber(r.share(SolutionClass::kPhysicalUnstable))},
                      {"non_physical", JsonNumber(r.share(SolutionClass::kNonPhysical))}}},
          {"solve_cpu_seconds", r.solve_seconds},
          {"clusters", clusters}};
}

// The second opinion: the Floquet multipliers of the original equations
// integrated over one period from the solution's state.
std::function<OriginalCheck(const HarmonicSolution&)> FloquetCheck(const Model& model) {
  return [&model](const HarmonicSolution& s) {
    integrators::FloquetOptions fo;
    fo.autonomous = model.problem.num_unknown_frequencies() > 0;
    if (model.stiff) fo.integrator.method = integrators::IntegratorOptions::Method::kBdf;
    const integrators::FloquetReport f = integrators::FloquetMultipliers(
        model.original(s.frequencies()), model.state(s, 0.0), 0.0, 2 * M_PI / s.frequencies()[0], fo);
    return OriginalCheck{f.ok, f.stable, f.multipliers, f.closure_error, f.message};
  };
}

}  // namespace

const char* ToString(CensusStatus status) {
  return status == CensusStatus::kCompleted ? "completed" : "none_converged";
}

CensusSummary Census(const Model& model, const CensusOptions& o, const MonteCarloRunner& run) {
  if (const std::string error = o.IsValid(); !error.empty()) throw std::invalid_argument("Monte Carlo: " + error);
  CensusSummary s;
  s.options = o.monte_carlo;
  if (model.original && o.floquet) s.options.original_check = FloquetCheck(model);
  s.monte_carlo = run ? run(model.problem, s.options) : RunMonteCarlo(model.problem, s.options);
  for (const auto& r : s.monte_carlo.rules)
    if (r.converged == 0) {
      s.status = CensusStatus::kNoneConverged;
      s.message = std::string(ToString(r.rule)) + " converged from none of the " +
                  std::to_string(s.monte_carlo.starts) + " starts";
    }
  s.options.original_check = nullptr;  // it refers to the model
  s.options.progress = nullptr;
  return s;
}

std::string CensusSummary::FullReport() const {
  char head[512];
  std::snprintf(head, sizeof head,
                "%ld starts, every unknown coefficient uniform in [%g, %g], seed %llu; reference: "
                "alias-free RHB at order %d; %d threads x %d rank(s), %.3f s\n\n",
                monte_carlo.starts, options.low, options.high, static_cast<unsigned long long>(options.seed),
                monte_carlo.reference_order, monte_carlo.threads, ranks, monte_carlo.seconds);
  return head + monte_carlo.FullReport();
}

json CensusSummary::ToJson() const {
  json methods = json::array();
  for (const auto& r : monte_carlo.rules) methods.push_back(RuleJson(r));
  return {{"starts", monte_carlo.starts},       {"range", {options.low, options.high}},
          {"seed", options.seed},               {"order", monte_carlo.order},
          {"reference_order", monte_carlo.reference_order}, {"match_tolerance", options.match_tolerance},
          {"threads", monte_carlo.threads},     {"ranks", ranks},
          {"seconds", monte_carlo.seconds},     {"methods", methods}};
}

}  // namespace rmhb
