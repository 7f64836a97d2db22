#ifndef RMHB_SEEDING_IDENTIFIED_GUESS_H_
#define RMHB_SEEDING_IDENTIFIED_GUESS_H_

// A starting guess for (quasi-)periodic harmonic balance measured on a
// trajectory: integrate the original equations (CVODE), identify the base
// frequencies and label every spectral line (frequency_id/), and turn the
// labelled lines into the base frequencies and Fourier coefficients of every
// variable on the solver's basis.
//
// Why it works where a guess must be good: the identification gives the
// frequencies to ~1e-11 and every line's amplitude and phase, so Newton starts
// next to the solution even on a slow beat (the asymmetric pendulum), with no
// model-specific guess code.
//
// What has to agree:
//  - coordinates. Base selection returns *a* basis of the frequency lattice,
//    e.g. (beat, w1) for the asymmetric pendulum where the problem's bases
//    are (w1, w2) = (w1, w1 + beat). The problem's own frequencies (values of
//    the known ones, guesses of the unknown ones) pick the coordinates: the
//    unimodular integer change of basis that brings the identified bases
//    closest to them. The guesses need only be closer than half the lattice
//    spacing (the paper's FFT estimates 0.9857, 0.9935 are enough).
//  - phases. Identified phases refer to t = 0 of the record's time axis,
//    which is the integration's: a conservative motion started at the
//    conditions' initial state is then already right at t = 0. On an
//    attractor the torus point at t = 0 is wherever the transient left it;
//    the angles of the unknown (autonomous) bases are turned to meet the
//    problem's point conditions (a phase condition such as x'(0) = 0), by a
//    scan then Gauss-Newton. Known (forcing) bases keep their phase.
//  - variables. The record holds the original state; the recast's
//    auxiliaries (sin(theta), 1/R, ...) are their definitions evaluated on the
//    reconstructed state, then everything is projected on the basis.

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "frequency_id/frequency_identification.h"
#include "frequency_id/signal.h"
#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_solution.h"

namespace rmhb::seeding {

// ---- The record ---------------------------------------------------------------
struct RecordOptions {
  double transient = 0;  // integrated from t = 0, not recorded
  double t_end = 0;      // the record is [transient, t_end)
  double dt = 0;         // sample spacing
  integrators::IntegratorOptions integrator;
};

// Record lengths for identification from (rough) base frequencies: enough
// periods of the slowest base for round-off refinement, and enough periods of
// the closest pair's beat that their lines stand several Hann^q main lobes
// apart. The transient is a tenth of the record, dt gives
// `samples_per_period` samples per period of the fastest base.
RecordOptions DefaultRecord(const std::vector<double>& frequencies, int samples_per_period = 16,
                            double periods = 200, double beats = 3);

// The trajectory from y0 at t = 0, sampled uniformly. Throws
// std::invalid_argument on bad options (t_end <= transient, dt <= 0, more
// than 20 million samples) and std::runtime_error when the integration fails.
frequency_id::Signal RecordTrajectory(const integrators::OdeSystem& system,
                                      const Eigen::VectorXd& y0, const RecordOptions& options,
                                      std::vector<std::string> channel_names = {});
// The same for a DAE (SUNDIALS IDA; y'(0) and the algebraic part of y0 are
// made consistent by IDACalcIC).
frequency_id::Signal RecordTrajectory(const integrators::DaeSystem& system,
                                      const Eigen::VectorXd& y0, const RecordOptions& options,
                                      std::vector<std::string> channel_names = {});

// ---- The guess ----------------------------------------------------------------
// Every harmonic balance variable at torus angles theta from the original
// state there and its time derivatives: state[j] = d^j y / dt^j.
using StateToVariables = std::function<Eigen::VectorXd(const std::vector<double>& theta,
                                                       const std::vector<Eigen::VectorXd>& state)>;

struct IdentifiedGuess {
  HarmonicSolution guess;
  // Identified base frequencies in the problem's order and coordinates.
  std::vector<double> frequencies;
  std::vector<double> uncertainties;
  // Problem base b = sum_i coordinates[b][i] * identified base i.
  std::vector<std::vector<int>> coordinates;
  // Turn of each base's angle applied to meet the conditions (0 for known).
  std::vector<double> phase_shift;
  double condition_residual = 0;  // max |r| of the problem's conditions on `guess`
  // Share of the labelled lines' energy whose harmonics the basis holds.
  double energy_on_basis = 0;
  int lines_used = 0;     // labelled lines on the basis
  int lines_dropped = 0;  // labelled lines off the basis, and unlabelled ones
  // One base with the record given: harmonics fitted on the record directly
  // (0: the guess is made of the identified lines).
  int fitted_harmonics = 0;
  // One base with one exact period given: its harmonics by the DFT (0: not).
  int period_harmonics = 0;
  std::string Report() const;  // one paragraph
};

// The identification's channels are the original state (as many as
// `variables` expects in state[0]); `state_derivatives` is how many time
// derivatives of it `variables` needs. Throws std::invalid_argument when the
// identification is not usable or its number of bases differs from the
// problem's, or when no integer change of basis matches the problem's known
// frequencies.
//
// With one base and the identified `record`, the state is instead fitted on
// every harmonic of the basis below 0.8 Nyquist at the identified frequency
// (least squares over the record's last periods): a relaxation oscillation
// has hundreds of harmonics, more than identification models as lines
// (max_components) or labels (max_harmonic).
//
// With one base and `period` (one exact period of the state sampled
// uniformly, e.g. by OnePeriod), the harmonics are those of the period (DFT,
// every one of the basis below its Nyquist) and the frequency is
// 2 pi / its length: no fit, no identification error.
IdentifiedGuess GuessFromIdentification(const frequency_id::IdentificationSummary& identification,
                                        const HarmonicBalanceProblem& problem,
                                        const HarmonicBasis& basis,
                                        const StateToVariables& variables,
                                        int state_derivatives = 0,
                                        const frequency_id::Signal* record = nullptr,
                                        const frequency_id::Signal* period = nullptr);

// The same from one exact period alone (as OnePeriod gives it), no
// identification: one unknown base, w = 2 pi / its length, the harmonics
// its DFT's, the angle turned to meet the problem's conditions. Throws
// std::invalid_argument for a problem that is not one unknown base.
IdentifiedGuess GuessFromPeriod(const HarmonicBalanceProblem& problem, const HarmonicBasis& basis,
                                const StateToVariables& variables, int state_derivatives,
                                const frequency_id::Signal& period);

// One period of an autonomous orbit through the state y0 (on the orbit,
// e.g. a record's settled last sample): its length is the first return to
// the section through y0 (integrators::SectionReturns) within 20 % of
// `period_guess` and within 1e-6 max(1, |y0|) of y0, and its `samples` states
// at t0 + m T / samples. nullopt when there is no such return (not periodic,
// or a period far from the guess).
std::optional<frequency_id::Signal> OnePeriod(const integrators::OdeSystem& system, const Eigen::VectorXd& y0,
                                              double t0, double period_guess, int samples,
                                              const integrators::IntegratorOptions& options);

// The highest harmonic of `period` (as OnePeriod gives it) whose largest
// coefficient over the channels exceeds `floor` times the largest harmonic's:
// the order a harmonic balance of that orbit needs to reach ~floor.
int PeriodOrder(const frequency_id::Signal& period, double floor);

}  // namespace rmhb::seeding

#endif  // RMHB_SEEDING_IDENTIFIED_GUESS_H_
