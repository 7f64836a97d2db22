#include "rmhb/pipeline/stability.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "rmhb/bifurcation.h"
#include "rmhb/pipeline/monodromy.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/truncation_estimate.h"

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
  r.max_modulus = JudgedModulus(r.multipliers, r.trivial, o.neutral_band);
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

StabilityVerdict FromPointStability(PointStability p) {
  switch (p) {
    case PointStability::kStable: return StabilityVerdict::kStable;
    case PointStability::kUnstable: return StabilityVerdict::kUnstable;
    case PointStability::kNeutral: return StabilityVerdict::kNeutral;
    default: return StabilityVerdict::kUnknown;
  }
}

StabilityVerdict ExponentVerdict(double largest, double band) {
  return largest < -band ? StabilityVerdict::kStable
         : largest > band ? StabilityVerdict::kUnstable
                          : StabilityVerdict::kNeutral;
}

// Hill's real parts against the Lyapunov exponents, both by value.
double ExponentDifference(const HillStabilityReport& hill, const TorusStabilityReport& lyapunov) {
  std::vector<double> a, b = lyapunov.exponents;
  for (const auto& l : hill.exponents) a.push_back(l.real());
  std::sort(a.rbegin(), a.rend());
  std::sort(b.rbegin(), b.rend());
  double worst = 0;
  for (size_t i = 0; i < std::min(a.size(), b.size()); ++i) worst = std::max(worst, std::abs(a[i] - b[i]));
  return worst;
}

}  // namespace

StabilitySummary TorusStabilityFrom(const HarmonicBalanceProblem& problem, const HarmonicSolution& torus,
                                    TorusStabilityReport lyapunov, const StabilityOptions& o) {
  StabilitySummary s;
  const std::vector<double>& w = torus.frequencies();
  s.exponent_band = o.neutral_band * *std::min_element(w.begin(), w.end()) / (2 * M_PI);
  s.neutral_band = o.neutral_band;
  try {
    s.hill = HillStability(problem, torus);
    s.hill_verdict = ExponentVerdict(s.hill->max_real_part, s.exponent_band);
  } catch (const std::invalid_argument& e) {
    s.hill_note = std::string("Hill's method refused: ") + e.what();
  } catch (const std::runtime_error& e) {  // an eigensolver that did not converge
    s.hill_note = std::string("Hill's method failed: ") + e.what();
  }
  s.floquet_note = "a torus has no period, so no monodromy matrix: Lyapunov exponents instead";
  s.lyapunov = std::move(lyapunov);
  // A failed integration still judges when the trajectory left the torus first.
  if (s.lyapunov->ok || s.lyapunov->stability == PointStability::kUnstable)
    s.lyapunov_verdict = FromPointStability(s.lyapunov->stability);
  const bool lyapunov_ok = s.lyapunov->ok && s.lyapunov_verdict != StabilityVerdict::kUnknown;
  // A trajectory that left the torus has exponents of where it went.
  const bool on_torus = s.lyapunov->departure <= TorusStabilityReport::kLeftTorus;
  if (s.hill && s.lyapunov->ok && on_torus) s.max_exponent_difference = ExponentDifference(*s.hill, *s.lyapunov);
  const bool hill_decides = s.hill && (!lyapunov_ok || s.agree());
  if (hill_decides) {
    s.verdict = s.hill_verdict;
    s.largest_exponent = s.hill->max_real_part;
    s.judged_by = "Hill";
  } else if (lyapunov_ok) {
    s.verdict = s.lyapunov_verdict;
    s.largest_exponent = s.lyapunov->max_exponent;
    s.exponent_band = s.lyapunov->tolerance;
    s.judged_by = "Lyapunov";
  }
  if (!s.judged_by.empty() && problem.num_unknown_frequencies() > 0) s.judged_by += ", the trivial exponents left out";
  return s;
}

bool StabilitySummary::agree() const {
  if (!torus()) return hill_verdict == floquet_verdict;
  // No exponents but a trajectory that left the torus is still a verdict.
  if (!hill || !(lyapunov->ok || lyapunov_verdict != StabilityVerdict::kUnknown)) return false;
  return hill_verdict == lyapunov_verdict ||
         (lyapunov_verdict == StabilityVerdict::kNeutral && std::abs(hill->max_real_part) <= lyapunov->tolerance);
}

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
  if (!(neutral_band >= 0 && neutral_band < 1)) return "neutral_band must be in [0, 1)";
  return torus.IsValid();
}

StabilityVerdict MultiplierVerdict(const Multipliers& mu, int trivial, double band) {
  const double largest = JudgedModulus(mu, trivial, band);
  return largest < 1 - band ? StabilityVerdict::kStable
         : largest > 1 + band ? StabilityVerdict::kUnstable
                              : StabilityVerdict::kNeutral;
}

StabilitySummary Stability(const Model& model, const HarmonicSolution& solution, const StabilityOptions& options) {
  if (const std::string error = options.IsValid(); !error.empty())
    throw std::invalid_argument("stability: " + error);
  if (solution.frequencies().size() != 1)
    return TorusStabilityFrom(model.problem, solution, TorusStability(model, solution, options.torus), options);
  StabilitySummary s;
  bool widened = false;
  StabilityOptions o = options;
  o.neutral_band = NeutralBand(solution, options.neutral_band, &widened);
  HillPart(model, solution, o, &s);
  FloquetPart(model, solution, o, &s);
  const bool floquet_ok = s.floquet && s.floquet->ok;
  if (s.hill && floquet_ok) s.max_multiplier_difference = MatchedDifference(s.hill->multipliers, s.floquet->multipliers);
  s.verdict = floquet_ok ? s.floquet_verdict : s.hill ? s.hill_verdict : StabilityVerdict::kUnknown;
  s.neutral_band = o.neutral_band;
  auto judge = [&s, widened](const Multipliers& mu, int trivial, const char* by) {
    bool paired = false;
    s.largest_modulus = JudgedModulus(mu, trivial, s.neutral_band, &paired);
    s.judged_by = std::string(by) + (paired ? ", the trivial multiplier and its partner by their geometric mean "
                                              "(a double 1 split by the orbit's error)"
                                   : trivial >= 0 ? ", the trivial multiplier left out" : "");
    if (widened)
      s.judged_by += StringPrintf("; the band is %g times the orbit's estimated error", kMultiplierErrorPerTruncation);
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

void AppendExponents(const HillStabilityReport& hill, std::string* out) {
  char text[128];
  for (size_t i = 0; i < hill.exponents.size(); ++i) {
    const auto& l = hill.exponents[i];
    const bool trivial = std::count(hill.trivials.begin(), hill.trivials.end(), static_cast<int>(i)) > 0;
    std::snprintf(text, sizeof text, " %.10g%+.10gi%s", l.real(), l.imag(), trivial ? " (trivial)" : "");
    *out += text;
  }
}

// The torus' lines: Hill's exponents, the Lyapunov exponents, their agreement.
std::string TorusReport(const StabilitySummary& s) {
  std::string out;
  char text[256];
  if (s.hill) {
    std::snprintf(text, sizeof text, "stability    %-8s %-8s exponents", "Hill", ToString(s.hill_verdict));
    out += text;
    AppendExponents(*s.hill, &out);
    std::snprintf(text, sizeof text, "; order %d, %d rows, %.3g ms\n", s.hill->order, s.hill->size,
                  s.hill->seconds * 1e3);
    out += text;
  } else {
    out += "stability    Hill: " + s.hill_note + "\n";
  }
  out += "stability    Lyapunov " + s.lyapunov->BriefReport() + "\n";
  if (s.max_exponent_difference) {
    std::snprintf(text, sizeof text,
                  "stability    the two agree to %.3e (max |Re lambda_Hill - lambda_Lyapunov|, Lyapunov tolerance %.1e), "
                  "verdicts %s\n",
                  *s.max_exponent_difference, s.lyapunov->tolerance, s.agree() ? "agree" : "DISAGREE");
    out += text;
  } else if (s.hill && s.lyapunov->ok) {
    out += std::string("stability    verdicts ") + (s.agree() ? "agree" : "DISAGREE") +
           " (the exponents are not compared: the trajectory left the torus)\n";
  }
  return out;
}

// A periodic solution's lines: Hill's and CVODE's multipliers, their agreement.
std::string PeriodicReport(const StabilitySummary& s) {
  std::string out;
  char text[256];
  if (s.hill) {
    std::snprintf(text, sizeof text, "stability    %-8s %-8s multipliers", "Hill", ToString(s.hill_verdict));
    out += text;
    AppendMultipliers(s.hill->multipliers, &out);
    out += "\n";
  } else {
    out += "stability    Hill: " + s.hill_note + "\n";
  }
  if (!s.floquet) {
    out += "stability    CVODE: " + s.floquet_note + "\n";
  } else if (!s.floquet->ok) {
    out += "stability    CVODE: integration failed: " + s.floquet->message + "\n";
  } else {
    std::snprintf(text, sizeof text, "stability    %-8s %-8s multipliers", "CVODE", ToString(s.floquet_verdict));
    out += text;
    AppendMultipliers(s.floquet->multipliers, &out);
    out += "\n";
  }
  if (s.max_multiplier_difference && std::isfinite(*s.max_multiplier_difference)) {
    std::snprintf(text, sizeof text, "stability    the two agree to %.3e (max |mu_Hill - mu_CVODE|), verdicts %s\n",
                  *s.max_multiplier_difference, s.agree() ? "agree" : "DISAGREE");
    out += text;
  }
  return out;
}

}  // namespace

std::string StabilitySummary::FullReport() const {
  const std::string judged = Judged();
  return (torus() ? TorusReport(*this) : PeriodicReport(*this)) + "stability    " + ToString(verdict) +
         (judged.empty() ? "" : ": " + judged) + "\n";
}

// "largest |mu| 0.811038697498 < 1 - 1e-06 (CVODE)": the number the verdict
// judged and the band it was judged against.
std::string StabilitySummary::Judged() const {
  if (judged_by.empty()) return "";
  if (torus()) {
    const char* relation = verdict == StabilityVerdict::kStable     ? "< -"
                           : verdict == StabilityVerdict::kUnstable ? "> +"
                                                                    : "within -+";
    char text[200];
    std::snprintf(text, sizeof text, "largest Re(lambda) %.10g %s%.2g (%s)", largest_exponent, relation,
                  exponent_band, judged_by.c_str());
    return text;
  }
  const char* relation = verdict == StabilityVerdict::kStable     ? "< 1 -"
                         : verdict == StabilityVerdict::kUnstable ? "> 1 +"
                                                                  : "within 1 -+";
  return StringPrintf("largest |mu| %.12g %s %.2g (", largest_modulus, relation, neutral_band) + judged_by + ")";
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
                   {"trivials", hill->trivials},
                   {"order", hill->order},
                   {"size", hill->size},
                   {"seconds", hill->seconds}};
  else
    out["hill"] = {{"note", hill_note}};
  if (torus()) {
    if (hill) out["hill"].erase("multipliers");
    out["floquet"] = {{"note", floquet_note}};
    const TorusStabilityReport& l = *lyapunov;
    out["lyapunov"] = {{"ok", l.ok}, {"verdict", ToString(lyapunov_verdict)}, {"exponents", l.exponents},
                       {"trivial", l.trivial}, {"max_exponent", JsonNumber(l.max_exponent)},
                       {"tolerance", JsonNumber(l.tolerance)}, {"departure", JsonNumber(l.departure)},
                       {"time", l.time}, {"steps", l.steps},
                       {"seconds", l.seconds}, {"message", l.message}};
    if (max_exponent_difference) out["max_exponent_difference"] = JsonNumber(*max_exponent_difference);
    if (hill && l.ok) out["agree"] = agree();
    out["verdict"] = ToString(verdict);
    if (!judged_by.empty())
      out["judged"] = {{"largest_exponent", JsonNumber(largest_exponent)}, {"band", exponent_band}, {"by", judged_by}};
    return out;
  }
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
  out << "stability: " << ToString(verdict) << " (Hill " << ToString(hill_verdict);
  if (torus()) {
    out << ", Lyapunov " << ToString(lyapunov_verdict);
    if (max_exponent_difference) out << ", exponents agree to " << *max_exponent_difference;
  } else {
    out << ", monodromy " << ToString(floquet_verdict);
    if (max_multiplier_difference) out << ", multipliers agree to " << *max_multiplier_difference;
  }
  out << ")";
  if (const std::string judged = Judged(); !judged.empty()) out << "; " << judged;
  out << "\n";
  return out.str();
}

}  // namespace rmhb
