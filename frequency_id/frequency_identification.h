#ifndef RMHB_FREQUENCY_ID_FREQUENCY_IDENTIFICATION_H_
#define RMHB_FREQUENCY_ID_FREQUENCY_IDENTIFICATION_H_

#include <string>
#include <vector>

#include <Eigen/Core>

#include "frequency_id/base_selection.h"
#include "frequency_id/frequency_refinement.h"
#include "frequency_id/signal.h"

namespace rmhb::frequency_id {

// Finds the base frequencies of a periodic or quasi-periodic record to
// near machine precision (Laskar's NAFF, carried to round-off):
//
//  1. Detection. The strongest peak of the windowed residual spectrum (FFTW)
//     is refined by maximising |phi(omega)|^2 on the samples (NLopt, then
//     Newton on the derivative), its amplitudes are fitted, and it is removed
//     from the residual; repeat. All lines found so far are polished jointly
//     (weighted nonlinear least squares over every frequency and amplitude,
//     see SinusoidFitter) before a peak much weaker than the current round,
//     or a peak next to a line not yet polished, is taken: the small errors
//     of strong lines must not masquerade as weak lines.
//  2. Window order. Detection starts with Hann (q = 1, the narrowest main
//     lobe). Unless forced, q is then raised as far as the smallest line
//     spacing allows, all lines are re-polished with it, and detection
//     resumes on the cleaner residual.
//  3. Final polish and joint least-squares fit of all amplitudes, standard
//     errors of the frequencies.
//  4. Base selection and integer labels (see SelectBases).
//
// When the record is an exact sum of the detected lines, step 3 solves the
// least-squares problem exactly, so the frequencies are limited by round-off
// (and noise), not by the record length. Lines left out (below the
// thresholds, beyond max_components) bias the fit only through the window's
// leakage, which falls like T^-(2q+2): that is what the window order buys.
//
// Limits: lines within (q+1) bins of 0 or of Nyquist are not searched for
// (the mean is fitted, though); non-stationary records (chirps, transients,
// drifts) end with status kNoConvergence.
struct IdentificationOptions {
  // ---- Detection ----------------------------------------------------------
  // Peaks weaker than relative_threshold times the strongest line's amplitude
  // are not lines.
  double relative_threshold = 1e-10;
  // ... nor are peaks weaker than noise_threshold times the median of the
  // residual spectrum (about 8.5 noise standard deviations for white noise:
  // across ~10^5 bins that gives essentially no false lines).
  double noise_threshold = 10.0;
  int max_components = 64;
  // All lines are polished before taking a peak weaker than this fraction of
  // the first peak taken since the last polish. Must stay well below 1:
  // within a round the spectrum is not re-polished, and must stay above the
  // leakage of an unpolished line.
  double polish_dynamic_range = 1e-2;

  // ---- Window -------------------------------------------------------------
  // Order q of the Hann^q window; 0 chooses it from the line spacing.
  int window_order = 0;
  int max_window_order = 4;
  // Automatic q keeps lines lobe_separation main-lobe half-widths apart:
  // spacing >= lobe_separation * (q + 1) bins. Lines closer than that
  // (within one window) are also refined jointly, as one block.
  double lobe_separation = 2.0;

  // ---- Refinement ---------------------------------------------------------
  RefinementOptions refinement;
  // Sweeps of the final polish; polishes between detections take at most 10
  // (needing more means the record is not a sum of stationary lines).
  int max_polish_sweeps = 40;
  // See PolishOptions::tolerance.
  double polish_tolerance = 1e-12;

  // ---- Bases --------------------------------------------------------------
  BaseSelectionOptions bases;

  // False with a reason when an option is out of range.
  bool Validate(std::string* why) const;
};

// One spectral line, x_c(t) contains amplitude(c) cos(frequency t + phase(c)).
struct Component {
  double frequency = 0.0;              // rad per unit time
  double frequency_uncertainty = 0.0;  // standard error estimate
  Eigen::VectorXd amplitude;           // per channel, >= 0
  Eigen::VectorXd phase;               // per channel, at t = 0, in (-pi, pi]
  double amplitude_norm = 0.0;         // Euclidean norm of `amplitude`
  // Integer combination of the bases (one entry per base); empty when no
  // combination with bounded entries matches within tolerance.
  std::vector<int> label;
  double lattice_residual = 0.0;  // frequency - label . bases (NaN if unlabelled)

  bool explained() const { return !label.empty(); }
};

enum class IdentificationStatus {
  kSuccess,                // every line found is explained by the bases
  kUnexplainedComponents,  // bases found, but some lines carry no label
  kNoConvergence,          // polishing did not converge: the record is not a
                           // sum of stationary lines; results are unreliable
  kNoComponents,           // nothing above the thresholds
  kInvalidInput,           // bad signal or options; see message
};
const char* ToString(IdentificationStatus status);

struct IdentificationSummary {
  IdentificationStatus status = IdentificationStatus::kInvalidInput;
  std::string message;

  std::vector<BaseFrequency> bases;
  std::vector<Component> components;  // strongest first
  Eigen::VectorXd mean;               // per channel
  Eigen::VectorXd residual_rms;       // per channel, window-weighted

  // Problem.
  int num_samples = 0;
  int num_channels = 0;
  double dt = 0.0;
  double duration = 0.0;  // N dt
  std::vector<std::string> channel_names;

  // Method.
  int window_order = 0;
  bool window_order_automatic = false;
  double min_line_spacing_bins = 0.0;  // between detected lines, in 2 pi / T
  int num_polishes = 0;
  int polish_sweeps = 0;               // total over all polishes
  bool polish_converged = false;       // the final polish
  double polish_last_change = 0.0;     // its convergence measure
  int largest_cluster = 0;             // most lines refined as one block
  int pruned_lines = 0;                // coincident or empty lines removed
  // Lines stopped being added because polishing between detections did not
  // converge: the record is not a sum of stationary lines (a chirp, a
  // transient, a drift). The lines found so far are still reported.
  bool detection_stopped_early = false;
  int line_refinements = 0;            // NLopt + Newton runs
  int refinement_evaluations = 0;      // |phi|^2 evaluations they used
  int num_explained = 0;
  double explained_energy_fraction = 0.0;
  int num_candidate_bases_tried = 0;

  // Wall-clock seconds.
  double detection_seconds = 0.0;   // peaks, line refinement, intermediate polishes
  double fitting_seconds = 0.0;     // final polish, joint fit, standard errors
  double base_selection_seconds = 0.0;
  double total_seconds = 0.0;

  bool IsUsable() const {
    return status == IdentificationStatus::kSuccess ||
           status == IdentificationStatus::kUnexplainedComponents;
  }
  std::string BriefReport() const;
  std::string FullReport() const;
};

// Returns summary->IsUsable().
bool IdentifyFrequencies(const IdentificationOptions& options, const Signal& signal,
                         IdentificationSummary* summary);

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_FREQUENCY_IDENTIFICATION_H_
