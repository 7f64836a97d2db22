#include "rmhb/pipeline/stability.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "rmhb/pipeline/monodromy.h"
#include "rmhb/pipeline/report.h"

namespace rmhb {
namespace {

using Multipliers = std::vector<std::complex<double>>;

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

void HillPart(const Model& model, const HarmonicSolution& solution, const StabilityOptions& o, StabilitySummary* s) {
  try {
    s->hill = HillStability(model.problem, solution);
    s->hill_verdict = MultiplierVerdict(s->hill->multipliers, s->hill->trivial, o.neutral_band);
  } catch (const std::invalid_argument& e) {
    s->hill_note = std::string("Hill's method refused: ") + e.what();
  }
}

// A piecewise-smooth model: the event-located monodromy with the saltation
// matrices at its switches (METHOD.md s.15), at FloquetPart's tolerances; an
// integration across the kinks and jumps would smear them over a step (a
// relay's multipliers 0.2 off).
void SwitchedFloquetPart(const Model& model, const HarmonicSolution& solution, const StabilityOptions& o,
                         StabilitySummary* s) {
  ModelMonodromyOptions tight;
  const integrators::IntegratorOptions defaults;
  tight.relative_tolerance = defaults.relative_tolerance;
  tight.absolute_tolerance = defaults.absolute_tolerance;
  const MonodromyResult m = ModelMonodromy(model, solution, 1, tight);
  integrators::FloquetReport r;
  r.ok = m.ok;
  r.message = m.message;
  r.multipliers = m.multipliers;
  r.trivial = m.trivial;
  r.seconds = m.seconds;
  r.max_modulus = LargestModulus(r.multipliers, r.trivial);
  r.stable = r.max_modulus < 1 - o.neutral_band;
  s->floquet = std::move(r);
  s->floquet_integrator = m.integrator;
  if (s->floquet->ok)
    s->floquet_verdict = MultiplierVerdict(s->floquet->multipliers, s->floquet->trivial, o.neutral_band);
}

void FloquetPart(const Model& model, const HarmonicSolution& solution, const StabilityOptions& o,
                 StabilitySummary* s) {
  if (model.original_switched) return SwitchedFloquetPart(model, solution, o, s);
  if (!model.original) {
    s->floquet_note = "no monodromy matrix: " +
                      (model.original_dae ? std::string("the original system is a DAE") : model.original_error);
    return;
  }
  integrators::FloquetOptions options;
  options.autonomous = model.problem.num_unknown_frequencies() > 0;
  if (model.stiff) options.integrator.method = integrators::IntegratorOptions::Method::kBdf;
  const double w = solution.frequencies()[0];
  s->floquet = integrators::FloquetMultipliers(model.original(solution.frequencies()), model.state(solution, 0.0),
                                               0.0, 2 * M_PI / w, options);
  s->floquet_integrator = model.stiff ? "CVODE BDF" : "CVODE Adams";
  if (s->floquet->ok)
    s->floquet_verdict = MultiplierVerdict(s->floquet->multipliers, s->floquet->trivial, o.neutral_band);
}

}  // namespace

const char* ToString(StabilityVerdict verdict) {
  switch (verdict) {
    case StabilityVerdict::kStable: return "stable";
    case StabilityVerdict::kUnstable: return "unstable";
    case StabilityVerdict::kNeutral: return "neutral";
    case StabilityVerdict::kUnknown: return "unknown";
  }
  return "unknown";
}

std::string StabilityOptions::IsValid() const {
  return neutral_band >= 0 && neutral_band < 1 ? "" : "neutral_band must be in [0, 1)";
}

double LargestModulus(const Multipliers& mu, int trivial) {
  double largest = 0;
  for (size_t i = 0; i < mu.size(); ++i)
    if (static_cast<int>(i) != trivial) largest = std::max(largest, std::abs(mu[i]));
  return largest;
}

StabilityVerdict MultiplierVerdict(const Multipliers& mu, int trivial, double band) {
  const double largest = LargestModulus(mu, trivial);
  return largest < 1 - band ? StabilityVerdict::kStable
         : largest > 1 + band ? StabilityVerdict::kUnstable
                              : StabilityVerdict::kNeutral;
}

StabilitySummary Stability(const Model& model, const HarmonicSolution& solution, const StabilityOptions& options) {
  if (const std::string error = options.IsValid(); !error.empty())
    throw std::invalid_argument("stability: " + error);
  StabilitySummary s;
  if (solution.frequencies().size() != 1) {
    s.hill_note = s.floquet_note =
        "quasi-periodic solution: no period, so neither Hill's method (one base frequency) nor a monodromy "
        "matrix applies";
    return s;
  }
  HillPart(model, solution, options, &s);
  FloquetPart(model, solution, options, &s);
  const bool floquet_ok = s.floquet && s.floquet->ok;
  if (s.hill && floquet_ok) s.max_multiplier_difference = MatchedDifference(s.hill->multipliers, s.floquet->multipliers);
  s.verdict = floquet_ok ? s.floquet_verdict : s.hill ? s.hill_verdict : StabilityVerdict::kUnknown;
  s.neutral_band = options.neutral_band;
  auto judge = [&s](const Multipliers& mu, int trivial, const char* by) {
    s.largest_modulus = LargestModulus(mu, trivial);
    s.judged_by = std::string(by) + (trivial >= 0 ? ", the trivial multiplier left out" : "");
  };
  if (floquet_ok)
    judge(s.floquet->multipliers, s.floquet->trivial, "CVODE");
  else if (s.hill)
    judge(s.hill->multipliers, s.hill->trivial, "Hill");
  return s;
}

namespace {

void AppendMultipliers(const std::vector<std::complex<double>>& multipliers, std::string* out) {
  char text[128];
  for (const auto& m : multipliers) {
    std::snprintf(text, sizeof text, " %.10g%+.10gi (|%.6g|)", m.real(), m.imag(), std::hypot(m.real(), m.imag()));
    *out += text;
  }
}

}  // namespace

std::string StabilitySummary::FullReport() const {
  std::string out;
  char text[256];
  if (hill) {
    std::snprintf(text, sizeof text, "stability    %-8s %-8s multipliers", "Hill", ToString(hill_verdict));
    out += text;
    AppendMultipliers(hill->multipliers, &out);
    out += "\n";
  } else {
    out += "stability    Hill: " + hill_note + "\n";
  }
  if (!floquet) {
    out += "stability    CVODE: " + floquet_note + "\n";
  } else if (!floquet->ok) {
    out += "stability    CVODE: integration failed: " + floquet->message + "\n";
  } else {
    std::snprintf(text, sizeof text, "stability    %-8s %-8s multipliers", "CVODE", ToString(floquet_verdict));
    out += text;
    AppendMultipliers(floquet->multipliers, &out);
    out += "\n";
  }
  if (max_multiplier_difference && std::isfinite(*max_multiplier_difference)) {
    std::snprintf(text, sizeof text, "stability    the two agree to %.3e (max |mu_Hill - mu_CVODE|), verdicts %s\n",
                  *max_multiplier_difference, agree() ? "agree" : "DISAGREE");
    out += text;
  }
  const std::string judged = Judged();
  return out + "stability    " + ToString(verdict) + (judged.empty() ? "" : ": " + judged) + "\n";
}

// "largest |mu| 0.811038697498 < 1 - 1e-06 (CVODE)": the number the verdict
// judged and the band it was judged against.
std::string StabilitySummary::Judged() const {
  if (judged_by.empty()) return "";
  const char* relation = verdict == StabilityVerdict::kStable     ? "< 1 -"
                         : verdict == StabilityVerdict::kUnstable ? "> 1 +"
                                                                  : "within 1 -+";
  char text[160];
  std::snprintf(text, sizeof text, "largest |mu| %.12g %s %g (%s)", largest_modulus,
                relation, neutral_band, judged_by.c_str());
  return text;
}

nlohmann::json StabilitySummary::ToJson() const {
  nlohmann::json out = nlohmann::json::object();
  if (hill)
    out["hill"] = {{"verdict", ToString(hill_verdict)},
                   {"stable", hill->stable},
                   {"multipliers", JsonComplex(hill->multipliers)},
                   {"exponents", JsonComplex(hill->exponents)},
                   {"max_real_part", JsonNumber(hill->max_real_part)},
                   {"trivial", hill->trivial},
                   {"seconds", hill->seconds}};
  else
    out["hill"] = {{"note", hill_note}};
  if (floquet)
    out["floquet"] = {{"ok", floquet->ok},
                      {"verdict", ToString(floquet_verdict)},
                      {"stable", floquet->stable},
                      {"multipliers", JsonComplex(floquet->multipliers)},
                      {"trivial", floquet->trivial},
                      {"closure_error", JsonNumber(floquet->closure_error)},
                      {"integrator", floquet_integrator},
                      {"seconds", floquet->seconds},
                      {"message", floquet->message}};
  else
    out["floquet"] = {{"note", floquet_note}};
  if (max_multiplier_difference) {
    out["max_multiplier_difference"] = JsonNumber(*max_multiplier_difference);
    out["agree"] = agree();
  }
  out["verdict"] = ToString(verdict);
  if (!judged_by.empty())
    out["judged"] = {{"largest_modulus", largest_modulus}, {"neutral_band", neutral_band}, {"by", judged_by}};
  return out;
}

std::string StabilitySummary::BriefReport() const {
  std::ostringstream out;
  out << "stability: " << ToString(verdict) << " (Hill " << ToString(hill_verdict) << ", monodromy "
      << ToString(floquet_verdict);
  if (max_multiplier_difference) out << ", multipliers agree to " << *max_multiplier_difference;
  out << ")";
  if (const std::string judged = Judged(); !judged.empty()) out << "; " << judged;
  out << "\n";
  return out.str();
}

}  // namespace rmhb
