#ifndef RMHB_FREQUENCY_ID_BASE_SELECTION_H_
#define RMHB_FREQUENCY_ID_BASE_SELECTION_H_

#include <string>
#include <vector>

namespace rmhb::frequency_id {

// What base selection needs to know about a measured spectral line.
struct LineEstimate {
  double frequency = 0.0;    // > 0, rad per unit time
  double uncertainty = 0.0;  // standard error of `frequency`
  double energy = 0.0;       // power carried by the line (sum over channels of A^2/2)
};

struct BaseSelectionOptions {
  // 1, 2 or 3 independent base frequencies at most.
  int max_bases = 2;
  // Labels are integer vectors with every |entry| <= max_order.
  int max_order = 10;
  // A single base (periodic signal) may carry more harmonics than
  // max_order: its labels are bounded by max(max_order, max_harmonic), and
  // two frequencies with a ratio p/q, p and q up to that bound, count as
  // dependent. 128: a friction or contact cycle's odd harmonics reach 63
  // and beyond above 1e-8 (at 40 they were unexplained lines); a ratio of
  // independent bases is ~1/q^2 from every p/q, far beyond any tolerance.
  int max_harmonic = 128;
  // Frequencies that must be bases (e.g. a forcing frequency), used exactly
  // as given. They come first in the result, in the given order.
  std::vector<double> known_frequencies;
  // The strongest `num_candidates` lines (and the common divisors of
  // rationally related pairs of them) are tried as bases.
  int num_candidates = 10;
  // A line is labelled l when |f - l.bases| <= tolerance_factor * sigma +
  // relative_tolerance_floor * max(f, bases), sigma combining the standard
  // errors of f and of the bases. The floor guards against over-optimistic
  // error estimates; it is far below any lattice spacing that bounded labels
  // can produce.
  double tolerance_factor = 10.0;
  double relative_tolerance_floor = 1e-12;
  // Energy differences below this fraction of the total are ties.
  double energy_tolerance = 1e-10;
  // Re-estimate the (not known) bases by weighted least squares over all
  // labelled lines, weights 1 / sigma^2.
  bool refine_bases = true;
};

struct BaseFrequency {
  double frequency = 0.0;
  double uncertainty = 0.0;
  bool known = false;  // taken from known_frequencies
  int line = -1;       // index of the line labelled as this base alone, or -1
  // IdentifyFrequencies: how far the record's two halves disagree on the
  // base's line, when beyond its statistical error (then also the
  // uncertainty); 0 otherwise.
  double drift = 0.0;
};

struct BaseSelection {
  std::vector<BaseFrequency> bases;
  // Per input line: its integer label (one entry per base), or empty when no
  // combination with |entries| <= max_order matches within tolerance.
  std::vector<std::vector<int>> labels;
  // Per input line: frequency - label . bases (NaN when unlabelled).
  std::vector<double> lattice_residuals;
  int num_explained = 0;
  double explained_energy_fraction = 0.0;
  int num_candidate_bases_tried = 0;
  std::string message;
};

// Chooses the smallest set of independent base frequencies of which every
// significant line is a small-integer combination.
//
// Bases are not picked by amplitude: a combination tone may well be stronger
// than a base. Every set of r candidates (r = 1 .. max_bases, always
// containing the known frequencies) labels all lines; each set is then
// replaced by its best unimodular equivalent (the same lattice, so the same
// explained lines, in other coordinates) and scored, in order of priority, by
//   1. the energy it leaves unexplained (differences below energy_tolerance
//      are ties), then the number of lines it leaves unexplained;
//   2. how well the amplitudes fall geometrically with the label entries:
//      the Huber loss of the robust fit log A = c - sum_i s_i |l_i| over the
//      explained lines. In the physical coordinates the Fourier amplitudes
//      of a smooth quasi-periodic motion decay exponentially with each
//      |l_i|; in sheared coordinates such as (w2 - w1, w1) or (w1, 2 w1 - w2)
//      they do not. Unlike a norm of the labels, this still holds when a
//      combination tone outgrows a base, when near-resonant ladders
//      (k+1) w1 - k w2 dominate, and when the band limit cuts the label set
//      to a strip that a shear would make more compact; the robust loss
//      keeps a few resonantly enhanced lines from outvoting the trend. Used
//      from 2 (r + 1) explained lines on: with fewer, any coordinates fit
//      some decay;
//   3. ties (few lines, or a sublattice whose labels are multiples): the
//      amplitude-weighted sum of |l|^2, smaller labels winning; then how
//      many bases are lines themselves, and their energy.
// The rank r is the smallest one that the next rank does not beat by more
// than energy_tolerance in unexplained energy, or by explaining at least
// two more lines per added base (a base that explains only itself is
// noise or an unrelated tone, not a new frequency of the motion).
//
// Canonical form: bases positive; the known ones first as given, the others
// in increasing order. Returns false only for invalid options (message says
// why); a selection that leaves lines unexplained is still returned as true.
bool SelectBases(const std::vector<LineEstimate>& lines, const BaseSelectionOptions& options,
                 BaseSelection* selection);

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_BASE_SELECTION_H_
