#ifndef RMHB_PIPELINE_TORUS_H_
#define RMHB_PIPELINE_TORUS_H_

// Quasi-periodic solutions (tori) of a model beyond one solve (METHOD.md
// s.18): how well the basis resolves them, whether they attract, and the
// periodic orbits they lock into.
//  - OutermostCoefficients: the size of the coefficients on the rim of the
//    index set, the adequacy check along a branch of tori (any basis: the
//    rim is where the set ends, whatever its shape).
//  - TorusStability: Lyapunov exponents of the ORIGINAL equations on the
//    solved torus (integrators/lyapunov.h from the torus' state at t = 0,
//    a point of the torus): as many exponents vanish as the torus has free
//    angles (its unknown bases), the others decide.
//  - NearestResonance, LockedModel, LockedSolution: a forced torus whose
//    rotation number w2/w1 reaches p/q locks into a periodic orbit of base
//    w1/q (the torus' harmonic (m, n) becomes the periodic harmonic
//    m q + n p); rmhb/pipeline/branch.h follows those orbits across the
//    tongue.

#include <string>
#include <vector>

#include "rmhb/continuation.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

// For each variable, the root-sum-square of the coefficients on the rim of
// the index set (harmonics k for which k + 2 e_b, |k_b| raised by two, is
// outside the set for some base b: two layers of a diamond or box, so that
// a solution or set with one parity of harmonics still has a rim that is
// not zero by symmetry), relative to the root-sum-square of all its
// non-constant coefficients; the largest over the variables. A truncation
// estimate: the basis resolves the solution where this is small.
double OutermostCoefficients(const HarmonicSolution& solution);

struct TorusStabilityOptions {
  // Integrated over `periods` periods of the slowest base, re-orthonormalised
  // every `segment_periods` periods (each segment restarts CVODE, whose
  // first steps are small: fewer, longer segments are cheaper, as long as
  // the exponents' spread times a segment stays far below log(1/u) ~ 36).
  double periods = 100;
  double segment_periods = 2;
  double relative_tolerance = 1e-8;  // CVODE's
  // An exponent within max(tolerance * w_min, 3 * spread) of 0 is neither
  // growth nor decay (w_min the slowest base, spread the exponents' change
  // over the second half of the span: their convergence).
  double tolerance = 1e-3;
  std::string IsValid() const;
};

struct TorusStabilityReport {
  bool ok = false;
  std::string message;            // why not, or what the verdict doubts
  std::vector<double> exponents;  // by decreasing value
  // The `trivial` exponents closest to 0: one per free angle of the torus
  // (its unknown bases); the verdict is on the others.
  int trivial = 0;
  double trivial_max = 0;         // max |trivial exponent|
  double max_exponent = 0;        // the largest non-trivial exponent
  double tolerance = 0;           // judged against
  double spread = 0;              // integrators::LyapunovReport::spread
  // max over the segment ends of |y(t) - torus(t)| relative to max |torus|:
  // a trajectory from a point of a repelling torus leaves it (round-off
  // grows like e^{lambda t}), and its exponents are then those of where it
  // went. Above kLeftTorus the torus is unstable and the exponents are not
  // its own (message); `left_at` the first segment end past it.
  double departure = 0;
  double left_at = 0;
  static constexpr double kLeftTorus = 0.1;
  PointStability stability = PointStability::kUnknown;
  double time = 0;                // integrated span
  long steps = 0;
  double seconds = 0;
  std::string BriefReport() const;
};

// Throws std::invalid_argument for invalid options or a periodic solution;
// no original equations (or a DAE) and failed integrations are ok = false.
TorusStabilityReport TorusStability(const Model& model, const HarmonicSolution& torus,
                                    const TorusStabilityOptions& options = {});

// The rational p/q (1 <= q <= max_denominator) nearest to `ratio` (the
// smaller q on a tie).
struct Resonance {
  int p = 0, q = 1;
  double distance = 0;  // |ratio - p/q|
};
Resonance NearestResonance(double ratio, int max_denominator);

// Two bases, the first known (the forcing), the second unknown: the forced
// torus LockedModel and LockedPeriods take.
bool IsForcedTorus(const Model& model);
// Two bases, both unknown: an autonomous torus (coupled self-excited
// oscillators), whose frequencies lock too.
bool IsAutonomousTorus(const Model& model);

// A forced torus' motion, from the model's initial state: locked when its
// state at multiples of the forcing period T repeats every q periods
// (max |y((k + q) T) - y(k T)| over the last 3 max_denominator periods
// within `tolerance` times max |y|) after `transient` periods. The
// smallest such q, or 0 (quasi-periodic, or not settled). Its largest
// such difference for that q (or the smallest over q when 0) in *mismatch.
int LockedPeriods(const Model& model, int transient, int max_denominator, double tolerance, double* mismatch);
// The rotation number p/q of a locked orbit (a periodic solution on base
// w1/q): p is the harmonic with the largest amplitude in the first variable,
// the free oscillation the forcing entrained.
Resonance LockedResonance(const HarmonicSolution& locked, int q);

// A forced model with one known and one unknown base (w1 the forcing, w2
// free, fixed in phase by as many of the user's conditions as it has unknown
// bases) locked at w2 / w1 = p / q: one known base w1 / q, the phase
// conditions dropped, the original equations bound to (w1, p w1 / q). An
// autonomous torus (both bases unknown, two phase conditions): one unknown
// base w1 / q, the first condition kept (the orbit's phase), the second
// dropped. Throws std::invalid_argument for another kind of model.
Model LockedModel(const Model& model, const Resonance& lock);
// The torus at the rotation number p/q with its second angle shifted by
// `phase`: a periodic solution on base w1 / q (harmonic (m, n) -> m q + n p).
HarmonicSolution LockedSolution(const HarmonicSolution& torus, const Resonance& lock, double phase);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_TORUS_H_
