#ifndef RMHB_PIPELINE_START_H_
#define RMHB_PIPELINE_START_H_

// A solve that needs no hand-made guess:
//   StartedSolve s = SolveFromAnyStart(model, guess, options);
// Tries, in order, until one converges to a physical solution:
//  1. the given guess (the model's own `guess`, or rest: for a forced
//     system Newton's first step from zero is the linear response);
//  2. forced periodic models (every frequency known): a simulated start.
//     The original equations are integrated period by period until the
//     stroboscopic map settles (|y(kT) - y((k-1)T)| <= settle_tolerance
//     times the state's size) -- the attractor the motion reaches -- and the
//     record that follows, started at a multiple of the period so that the
//     forcing's phase is kept, seeds the solve (rmhb/pipeline/analyze.h with
//     the frequencies known);
//  3. models with unknown frequencies, and forced tori (two or more known
//     frequencies, no stroboscopic fixed point): identification from a
//     trajectory (the full Analyze pipeline; a forced torus recorded once two
//     motions have met, TorusSettleTime).
// The route taken is reported. Nothing is found: the last attempt's summary,
// with its residual.

#include <string>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

struct StartOptions {
  double settle_tolerance = 1e-9;  // relative change of the stroboscopic state
  int max_periods = 20000;         // integration budget of the simulated start
  double max_seconds = 10;         // wall-clock budget of the simulated start
  std::string IsValid() const;
};

struct StartedSolve {
  HarmonicBalanceSummary summary;
  std::string route;  // "guess", "simulation (K periods to settle)", "identification"
  std::string note;   // why earlier routes were left (empty when the first one worked)
  int settle_periods = 0;
};

// Why a start's summary is not kept, for a note: "not_converged, max|F| 0.4",
// "non-physical: ...", or an order and estimated error far from the target.
std::string WhyNotKept(const HarmonicBalanceSummary& s);

StartedSolve SolveFromAnyStart(const Model& model, const HarmonicSolution& guess,
                               const HarmonicBalanceOptions& options, const StartOptions& start = {});

// The state on the attractor at t = K T: integrated from the model's initial
// state period by period until the stroboscopic map settles. Sets *periods to
// K; throws std::runtime_error (with why) when it does not settle within the
// budget or the integration fails.
Eigen::VectorXd SettledState(const Model& model, const StartOptions& start, int* periods);

// A forced torus (every base frequency known, two or more) has no
// stroboscopic fixed point, but its forcing fixes every phase: all motions
// in the attractor's basin converge onto the same x(t). Two of them, from
// the model's initial state and 0.1 max(1, |y0|) off it in every state, are
// integrated side by side (explicit ODEs) in chunks of 25 slowest periods
// until they agree to settle_tolerance max(1, |y|): the time when they do,
// in periods of the slowest base via *periods. Throws std::runtime_error
// when they do not within the budget (another attractor, chaos) or the
// integration fails.
double TorusSettleTime(const Model& model, const StartOptions& start, int* periods);

// Where the record of a forced motion (every base frequency known) starts
// when no transient was given (identify, analyze): a periodic motion from
// its settled state (SettledState; the record then runs from t = 0 to its
// t_end), a torus from the model's start with the record moved past
// TorusSettleTime when that is later than its transient (as it was when the
// two motions do not meet). A damping of 0.1 leaves e^-5 of the start after
// a default transient, which the identification's polish cannot fit.
// Sets *periods (0: the record as it was); throws std::runtime_error when a
// periodic motion does not settle within the budget.
Eigen::VectorXd ForcedRecordStart(const Model& model, seeding::RecordOptions* record, int* periods);

// The record of a self-excited motion (one unknown frequency, explicit ODEs)
// when no transient was given (identify, analyze): from y0 (RecordStart)
// past the default transient, the motion's returns to the Poincare section
// through the state there (SectionReturns) are followed until two in a row
// agree to settle_tolerance max(1, |y|): its attractor's fixed point. A
// record that had not settled by its default transient (a limit cycle
// approached at a rate ~ its damping, as the Van der Pol family's) is moved
// past the settling time, *periods set to the returns it took; otherwise
// (settled by then, on an equilibrium, no returns, no contraction, the
// budget used up: a damped motion, a torus, chaos) the record is left as it
// was, *periods 0.
void SettleAutonomousRecord(const Model& model, const Eigen::VectorXd& y0, seeding::RecordOptions* record,
                            int* periods);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_START_H_
