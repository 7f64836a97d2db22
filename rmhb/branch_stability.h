#ifndef RMHB_BRANCH_STABILITY_H_
#define RMHB_BRANCH_STABILITY_H_

// The Floquet multipliers of the points of a branch (rmhb/continuation.h),
// by the method ContinuationOptions asks for: the monodromy of the harmonic
// balance linearisation (rmhb/harmonic_monodromy.h), Hill's method on the
// same linearisation (rmhb/hill_stability.h) or the monodromy matrix of the
// original equations (ContinuationProblem::monodromy). TraceBranch
// calls it at every point and at every trial point of a bifurcation's
// location. A method that does not apply to the problem (Hill: pinned
// auxiliaries) is not tried again; one that fails at a point (QZ did not
// converge, an integration failed) hands that point to the other.
//
// kAuto's rule (ContinuationOptions::stability) is deterministic; at its
// first point where two methods apply it computes every applicable one and
// reports how well they agree and what each cost (cross_check()).

#include <string>

#include "rmhb/continuation.h"

namespace rmhb {

class BranchStability {
 public:
  // `unknowns`: the size of the harmonic balance Jacobian (Hill's cost).
  BranchStability(const ContinuationProblem& problem, const ContinuationOptions& options, int unknowns);

  // Fills the stability fields of `point` (multipliers, verdict, method);
  // false when no method gave its multipliers (then note() says why).
  // `problem`: the harmonic balance problem at the point's parameter.
  bool Classify(const HarmonicBalanceProblem& problem, ContinuationPoint* point);

  const std::string& note() const { return note_; }
  // Both methods at kAuto's first point (empty when it did not compare).
  const std::string& cross_check() const { return cross_check_; }
  int hill_points() const { return hill_points_; }
  int harmonic_points() const { return harmonic_points_; }
  int monodromy_points() const { return monodromy_points_; }
  double seconds() const { return seconds_; }

 private:
  bool HillApplies() const { return !hill_refused_; }
  // kAuto's first point: every applicable method, compared; `point` gets
  // the one the rule picks. False when fewer than two gave multipliers
  // (then `point` has those of the one that did, if any: *done).
  bool Compare(const HarmonicBalanceProblem& problem, ContinuationPoint* point, bool* done);
  bool TryHarmonic(const HarmonicBalanceProblem& problem, ContinuationPoint* point);
  bool TryHill(const HarmonicBalanceProblem& problem, ContinuationPoint* point);
  bool TryMonodromy(ContinuationPoint* point);
  void Finish(const Multipliers& multipliers, int trivial, StabilityMethod method, ContinuationPoint* point) const;

  const ContinuationProblem& problem_;
  const ContinuationOptions& options_;
  int unknowns_;
  bool hill_refused_ = false;
  bool monodromy_refused_ = false;
  bool harmonic_refused_ = false;
  int hill_failures_ = 0;
  std::string note_, cross_check_;
  bool compared_ = false;
  int hill_points_ = 0, monodromy_points_ = 0, harmonic_points_ = 0;
  int harmonic_samples_ = 0;  // the grid the last point suggested (HarmonicMonodromy)
  double seconds_ = 0;
};

}  // namespace rmhb

#endif  // RMHB_BRANCH_STABILITY_H_
