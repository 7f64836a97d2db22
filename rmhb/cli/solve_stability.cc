#include "rmhb/cli/solve_stability.h"

#include <cmath>
#include <complex>
#include <optional>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "integrators/floquet.h"
#include "rmhb/cli/solve_setup.h"
#include "rmhb/hill_stability.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
using Multipliers = std::vector<std::complex<double>>;

json Complex(const Multipliers& values) {
  json out = json::array();
  for (const auto& v : values) out.push_back({Number(v.real()), Number(v.imag())});
  return out;
}

// Largest distance between the two sets, each of `a` paired with the
// nearest unused one of `b` (conjugate pairs come in either order).
double MatchedDifference(const Multipliers& a, const Multipliers& b) {
  std::vector<bool> used(b.size(), false);
  double worst = 0;
  for (const auto& mu : a) {
    int best = -1;
    for (size_t j = 0; j < b.size(); ++j)
      if (!used[j] && (best < 0 || std::abs(b[j] - mu) < std::abs(b[best] - mu))) best = int(j);
    if (best < 0) break;
    used[best] = true;
    worst = std::max(worst, std::abs(b[best] - mu));
  }
  return worst;
}

// Within this of the unit circle a multiplier is neither growth nor decay
// that a truncated (Hill) or tolerance-limited (CVODE) computation can
// decide: a conservative orbit's multipliers sit there (neutral).
constexpr double kNeutralBand = 1e-6;

std::string Verdict(const Multipliers& mu, int trivial) {
  double largest = 0;
  for (size_t i = 0; i < mu.size(); ++i)
    if (static_cast<int>(i) != trivial) largest = std::max(largest, std::abs(mu[i]));
  return largest < 1 - kNeutralBand ? "stable" : largest > 1 + kNeutralBand ? "unstable" : "neutral";
}

}  // namespace

json StabilityJson(const ProblemSource& source, const HarmonicSolution& solution) {
  json out = json::object();
  if (solution.frequencies().size() != 1) {
    const char* why = "quasi-periodic solution: no period, so neither Hill's method (one base "
                      "frequency) nor a monodromy matrix applies";
    out["hill"] = {{"note", why}};
    out["floquet"] = {{"note", why}};
    out["verdict"] = "unknown";
    return out;
  }
  std::optional<HillStabilityReport> hill;
  try {
    hill = HillStability(source.problem, solution);
    out["hill"] = {{"verdict", Verdict(hill->multipliers, hill->trivial)},
                   {"stable", hill->stable},
                   {"multipliers", Complex(hill->multipliers)},
                   {"exponents", Complex(hill->exponents)},
                   {"max_real_part", Number(hill->max_real_part)},
                   {"trivial", hill->trivial},
                   {"seconds", hill->seconds}};
  } catch (const std::invalid_argument& e) {
    out["hill"] = {{"note", std::string("Hill's method refused: ") + e.what()}};
  }
  std::optional<integrators::FloquetReport> floquet;
  if (source.original) {
    integrators::FloquetOptions options;
    options.autonomous = source.problem.num_unknown_frequencies() > 0;
    if (source.stiff) options.integrator.method = integrators::IntegratorOptions::Method::kBdf;
    const double w = solution.frequencies()[0];
    floquet = integrators::FloquetMultipliers(source.original(solution.frequencies()),
                                              source.state(solution, 0.0), 0.0, 2 * M_PI / w, options);
    out["floquet"] = {{"ok", floquet->ok},
                      {"verdict", floquet->ok ? Verdict(floquet->multipliers, floquet->trivial) : "unknown"},
                      {"stable", floquet->stable},
                      {"multipliers", Complex(floquet->multipliers)},
                      {"trivial", floquet->trivial},
                      {"closure_error", Number(floquet->closure_error)},
                      {"integrator", source.stiff ? "CVODE BDF" : "CVODE Adams"},
                      {"seconds", floquet->seconds},
                      {"message", floquet->message}};
  } else {
    out["floquet"] = {{"note", "no monodromy matrix: " + (source.original_dae
                                                              ? std::string("the original system is a DAE")
                                                              : source.original_error)}};
  }
  const bool floquet_ok = floquet && floquet->ok;
  if (hill && floquet_ok) {
    out["max_multiplier_difference"] = Number(MatchedDifference(hill->multipliers, floquet->multipliers));
    out["agree"] = out["hill"]["verdict"] == out["floquet"]["verdict"];
  }
  out["verdict"] = floquet_ok ? out["floquet"]["verdict"] : hill ? out["hill"]["verdict"] : json("unknown");
  return out;
}

void PrintStability(const json& s) {
  auto line = [](const char* name, const json& part) {
    if (part.contains("note")) {
      std::printf("stability    %s: %s\n", name, part["note"].get<std::string>().c_str());
      return;
    }
    if (part.contains("ok") && !part["ok"].get<bool>()) {
      std::printf("stability    %s: integration failed: %s\n", name, part["message"].get<std::string>().c_str());
      return;
    }
    std::printf("stability    %-8s %-8s multipliers", name, part["verdict"].get<std::string>().c_str());
    for (const auto& m : part["multipliers"]) {
      const double re = m[0].is_null() ? NAN : m[0].get<double>();
      const double im = m[1].is_null() ? NAN : m[1].get<double>();
      std::printf(" %.10g%+.10gi (|%.6g|)", re, im, std::hypot(re, im));
    }
    std::printf("\n");
  };
  line("Hill", s["hill"]);
  line("CVODE", s["floquet"]);
  if (s.contains("max_multiplier_difference") && !s["max_multiplier_difference"].is_null())
    std::printf("stability    the two agree to %.3e (max |mu_Hill - mu_CVODE|), verdicts %s\n",
                s["max_multiplier_difference"].get<double>(), s["agree"].get<bool>() ? "agree" : "DISAGREE");
  std::printf("stability    %s\n", s["verdict"].get<std::string>().c_str());
}

}  // namespace rmhb::cli
