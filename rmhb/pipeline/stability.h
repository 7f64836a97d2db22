#ifndef RMHB_PIPELINE_STABILITY_H_
#define RMHB_PIPELINE_STABILITY_H_

// The stability of a periodic solution two independent ways:
//   StabilitySummary s = Stability(model, solution);
// Hill's method on the harmonic balance linearisation (rmhb/hill_stability.h)
// and the Floquet multipliers of the CVODE monodromy matrix of the original
// equations (integrators/floquet.h), matched pairwise. The verdict is the
// monodromy's when it ran (it does not depend on the truncation), else
// Hill's. Where one does not apply (Hill: pinned auxiliaries, several base
// frequencies; monodromy: no original ODE) its note says why.
//
// A torus (two or more bases) has no period, so no multipliers: Hill's
// method gives its exponents (rmhb/hill_stability.h), the Lyapunov exponents
// of the original equations on it (rmhb/pipeline/torus.h) check them. Both
// judge the largest non-trivial exponent; the integration's tolerance is the
// coarser (its exponents converge like 1/t), so where it says neutral and
// Hill's exponent lies within that tolerance the two agree, and the verdict
// is Hill's; where they contradict each other the verdict is Lyapunov's (it
// does not depend on the truncation).

#include <complex>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "integrators/floquet.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/hill_stability.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/pipeline/torus.h"

namespace rmhb {

enum class StabilityVerdict { kStable, kUnstable, kNeutral, kUnknown };
const char* ToString(StabilityVerdict verdict);  // "stable", "unstable", "neutral", "unknown"

struct StabilityOptions {
  // Within this of the unit circle a multiplier is neither growth nor decay
  // that a truncated (Hill) or tolerance-limited (CVODE) computation can
  // decide: a conservative orbit's multipliers sit there (neutral).
  double neutral_band = 1e-6;
  // A torus' Lyapunov exponents; Hill's exponents are judged against the
  // same band per period of the slowest base, |Re lambda| 2 pi / w_min.
  TorusStabilityOptions torus;
  std::string IsValid() const;
};

struct StabilitySummary {
  std::optional<HillStabilityReport> hill;
  std::string hill_note;  // why there is no Hill result
  StabilityVerdict hill_verdict = StabilityVerdict::kUnknown;
  std::optional<integrators::FloquetReport> floquet;
  std::string floquet_note;  // why there is no monodromy matrix
  std::string floquet_integrator;
  StabilityVerdict floquet_verdict = StabilityVerdict::kUnknown;
  // Both ran: the largest distance between matched multipliers.
  std::optional<double> max_multiplier_difference;
  StabilityVerdict verdict = StabilityVerdict::kUnknown;
  // What the verdict judged: the largest |mu| (the trivial multiplier left
  // out; JudgedModulus) of the method it came from (CVODE's when it ran,
  // else Hill's), against 1 -+ neutral_band. NaN without a verdict.
  double largest_modulus = std::numeric_limits<double>::quiet_NaN();
  // "CVODE" or "Hill", then ", the trivial multiplier left out" or ", the
  // trivial multiplier and its partner by their geometric mean ..."
  // (JudgedModulus), and "; the band is 10 times the orbit's estimated
  // error" when NeutralBand widened neutral_band.
  std::string judged_by;
  double neutral_band = 0;

  // A torus: the Lyapunov exponents in place of the monodromy matrix, the
  // largest non-trivial exponent judged against -+ exponent_band.
  std::optional<TorusStabilityReport> lyapunov;
  StabilityVerdict lyapunov_verdict = StabilityVerdict::kUnknown;
  // Both ran: the largest distance between Hill's real parts and the
  // Lyapunov exponents, each sorted by value.
  std::optional<double> max_exponent_difference;
  double largest_exponent = std::numeric_limits<double>::quiet_NaN();
  double exponent_band = 0;

  bool torus() const { return lyapunov.has_value(); }
  // The two methods' verdicts are the same, or (a torus) Lyapunov's is
  // neutral with Hill's exponent within its tolerance.
  bool agree() const;
  std::string BriefReport() const;
  // One line per method ("stability    Hill     stable   multipliers ..."),
  // their agreement and the verdict (rmhb solve --stability).
  std::string FullReport() const;
  std::string Judged() const;  // the verdict's number and band, for the reports
  // {"hill": {...} | {"note"}, "floquet": {...} | {"note"},
  //  "max_multiplier_difference", "agree", "verdict"} (solve --json); a
  // torus: "lyapunov" and "max_exponent_difference" in place of "floquet"
  // and "max_multiplier_difference".
  nlohmann::json ToJson() const;
};

StabilitySummary Stability(const Model& model, const HarmonicSolution& solution, const StabilityOptions& options = {});
// A torus' summary with its Lyapunov exponents computed elsewhere (a branch
// point's): Hill's method on `problem`, the comparison and the verdict.
StabilitySummary TorusStabilityFrom(const HarmonicBalanceProblem& problem, const HarmonicSolution& torus,
                                    TorusStabilityReport lyapunov, const StabilityOptions& options = {});

// The verdict of a set of multipliers, the trivial one (index, or -1) left
// out: JudgedModulus (rmhb/bifurcation.h) against 1 -+ neutral_band.
StabilityVerdict MultiplierVerdict(const std::vector<std::complex<double>>& multipliers, int trivial,
                                   double neutral_band);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_STABILITY_H_
