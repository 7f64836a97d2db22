#include "frequency_id/frequency_identification.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>

#include "frequency_id/frequency_refinement.h"
#include "frequency_id/sample_grid.h"
#include "frequency_id/sinusoid_fit.h"
#include "frequency_id/spectrum.h"
#include "frequency_id/window.h"

namespace rmhb::frequency_id {
namespace {

constexpr int kMinSamples = 32;
// A refined peak this close to a known line (in bins) is that line's
// leftover, not a new line.
constexpr double kDuplicateBins = 0.05;
// Between detections the model only has to be clean below the next peak,
// which takes a few sweeps when the record is a sum of stationary lines.
// Needing more means it is not (a chirp, a transient): stop adding lines
// rather than spend O(lines^2) sweeps fitting it.
constexpr int kIntermediateSweeps = 10;
// Detection rounds (a peak taken, refined, added or rejected; a polish) per
// line the model may hold: every identification of the test suite needs at
// most 1.3 (42 rounds for 32 lines).
constexpr int kRoundsPerComponent = 4;

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double WrapPhase(double phase) {
  phase = std::remainder(phase, 2.0 * kPi);
  return phase <= -kPi ? phase + 2.0 * kPi : phase;
}

double MinSpacingBins(const SinusoidModel& model, double bin_width) {
  std::vector<double> f = model.frequencies;
  std::sort(f.begin(), f.end());
  double spacing = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < f.size(); ++i) spacing = std::min(spacing, f[i] - f[i - 1]);
  return spacing / bin_width;
}

// The detection / refinement state shared by the stages of one run.
class Identifier {
 public:
  Identifier(const IdentificationOptions& options, const Signal& signal,
             IdentificationSummary* summary)
      : options_(options),
        summary_(summary),
        grid_{signal.t0, signal.dt, signal.num_samples()} {
    SetWindow(options.window_order > 0 ? options.window_order : 1);
    fitter_ = std::make_unique<SinusoidFitter>(grid_, signal.samples, analyzer_->weights());
  }

  void SetWindow(int order) {
    window_order_ = order;
    analyzer_ = std::make_unique<SpectrumAnalyzer>(grid_, Window(order));
    if (fitter_) fitter_->SetWeights(analyzer_->weights());
  }

  int window_order() const { return window_order_; }
  SinusoidFitter& fitter() { return *fitter_; }
  bool stopped_early() const { return stopped_early_; }
  bool rounds_exhausted() const { return rounds_exhausted_; }

  PolishOptions MakePolishOptions(double tolerance) const {
    PolishOptions polish;
    polish.max_sweeps = options_.max_polish_sweeps;
    polish.tolerance = tolerance;
    polish.cluster_spacing =
        options_.lobe_separation * (window_order_ + 1.0) * grid_.BinWidth();
    return polish;
  }

  // Polishes all lines. Before the next, weaker peak at `next_level` is
  // taken, the model only has to be clean well below that level (0 asks for
  // the full tolerance).
  // Returns false if the polish did not converge.
  bool Polish(double next_level = 0.0) {
    fresh_.clear();
    const double tolerance =
        strongest_ > 0.0 ? std::max(options_.polish_tolerance, 1e-3 * next_level / strongest_)
                         : options_.polish_tolerance;
    PolishOptions polish_options = MakePolishOptions(tolerance);
    if (next_level > 0.0) {
      polish_options.max_sweeps = std::min(polish_options.max_sweeps, kIntermediateSweeps);
    }
    const PolishSummary polish = fitter_->Polish(polish_options);
    ++summary_->num_polishes;
    summary_->polish_sweeps += polish.sweeps;
    summary_->polish_converged = polish.converged;
    summary_->polish_last_change = polish.last_change;
    summary_->largest_cluster = std::max(summary_->largest_cluster, polish.largest_cluster);
    PruneDegenerateLines();
    return polish.converged;
  }

  // Two lines that polishing has pulled onto each other fit one line with
  // huge opposite amplitudes, and a line polished down to nothing was never
  // there: keep the stronger of such a pair, drop the empty ones.
  void PruneDegenerateLines() {
    const double bin = grid_.BinWidth();
    bool removed = true;
    while (removed && fitter_->num_lines() > 0) {
      removed = false;
      const SinusoidModel& model = fitter_->model();
      const int lines = model.num_lines();
      for (int i = 0; i < lines && !removed; ++i) {
        if (model.Amplitude(i) < options_.relative_threshold * strongest_) {
          rejected_.push_back(model.frequencies[i]);
          fitter_->RemoveLine(i);
          removed = true;
          break;
        }
        for (int j = i + 1; j < lines; ++j) {
          if (std::abs(model.frequencies[i] - model.frequencies[j]) <= kDuplicateBins * bin) {
            const int weaker = model.Amplitude(i) < model.Amplitude(j) ? i : j;
            rejected_.push_back(model.frequencies[weaker]);
            fitter_->RemoveLine(weaker);
            removed = true;
            break;
          }
        }
      }
      if (removed) {
        ++summary_->pruned_lines;
        fitter_->Polish(MakePolishOptions(options_.polish_tolerance));
      }
    }
  }

  // Takes lines from the residual spectrum, strongest first, until none is
  // left above the thresholds (see IdentificationOptions).
  void Detect() {
    if (stopped_early_) return;
    const double bin = grid_.BinWidth();
    // A line closer than a main lobe to 0 or to Nyquist overlaps its own
    // mirror image; the mean takes care of 0 itself.
    const double lobe = (window_order_ + 1.0) * bin;
    PeakSearchOptions search;
    search.min_frequency = lobe;
    search.max_frequency = grid_.Nyquist() - lobe;
    int unpolished = 0;
    double round_level = 0.0;  // first peak taken since the last polish
    // A line that polishing pulls away from its peak and then prunes is not
    // rejected at the peak's frequency: the peak came back, forever (a MEMS
    // file in SI units: 2759 polishes in 30 s). The rounds are bounded.
    const int max_rounds = kRoundsPerComponent * options_.max_components;
    int rounds = 0;
    while (fitter_->num_lines() < options_.max_components) {
      if (++rounds > max_rounds) {
        rounds_exhausted_ = true;
        break;
      }
      analyzer_->Compute(fitter_->residual());
      const double noise = analyzer_->MedianAmplitude(search.min_frequency, search.max_frequency);
      const std::vector<SpectralPeak> peaks = analyzer_->FindPeaks(search);
      const SpectralPeak* peak = nullptr;
      for (const SpectralPeak& p : peaks) {
        const bool was_rejected =
            std::any_of(rejected_.begin(), rejected_.end(),
                        [&](double f) { return std::abs(f - p.frequency) <= 1.5 * bin; });
        if (!was_rejected) {
          peak = &p;
          break;
        }
      }
      if (peak != nullptr && strongest_ == 0.0) strongest_ = peak->amplitude;
      const double threshold =
          std::max(options_.relative_threshold * strongest_, options_.noise_threshold * noise);
      const bool weak = peak == nullptr || peak->amplitude < threshold;
      // The residual next to a line not yet polished holds that line's
      // error, not new lines.
      const double cluster = options_.lobe_separation * lobe;
      const bool near_fresh_line =
          !weak && std::any_of(fresh_.begin(), fresh_.end(), [&](double f) {
            return std::abs(f - peak->frequency) < cluster;
          });
      if (unpolished > 0 && (weak || near_fresh_line ||
                             peak->amplitude < options_.polish_dynamic_range * round_level)) {
        const bool converged = Polish(weak ? 0.0 : peak->amplitude);
        unpolished = 0;
        round_level = 0.0;
        if (!converged && !weak) {
          stopped_early_ = true;
          break;
        }
        continue;
      }
      if (weak) break;
      if (round_level == 0.0) round_level = peak->amplitude;

      const Eigen::MatrixXd windowed = analyzer_->weights().asDiagonal() * fitter_->residual();
      const RefinedLine line =
          RefineLineFrequency(grid_, windowed, analyzer_->weight_sum(), peak->frequency - bin,
                              peak->frequency + bin, peak->frequency, options_.refinement);
      ++summary_->line_refinements;
      summary_->refinement_evaluations += line.evaluations;
      const auto& f = fitter_->model().frequencies;
      const bool duplicate = std::any_of(f.begin(), f.end(), [&](double existing) {
        return std::abs(existing - line.frequency) <= kDuplicateBins * bin;
      });
      if (duplicate) {
        if (unpolished > 0) {
          const bool converged = Polish(peak->amplitude);
          unpolished = 0;
          round_level = 0.0;
          if (!converged) {
            stopped_early_ = true;
            break;
          }
        } else {
          rejected_.push_back(peak->frequency);
        }
        continue;
      }
      fitter_->AddLine(line.frequency);
      fresh_.push_back(line.frequency);
      strongest_ = std::max(strongest_, line.amplitude);
      ++unpolished;
    }
    if (unpolished > 0) Polish();
  }

 private:
  const IdentificationOptions& options_;
  IdentificationSummary* summary_;
  SampleGrid grid_;
  int window_order_ = 1;
  std::unique_ptr<SpectrumAnalyzer> analyzer_;
  std::unique_ptr<SinusoidFitter> fitter_;
  double strongest_ = 0.0;
  std::vector<double> fresh_;  // lines added since the last polish
  // Peaks not to take again: leftovers of converged lines, and lines pruned
  // after polishing (re-adding them would loop).
  std::vector<double> rejected_;
  bool stopped_early_ = false;
  bool rounds_exhausted_ = false;
};

// Line k of the fit alone: the record without every other line and the
// mean (the fit's residual plus line k).
Eigen::MatrixXd IsolatedLine(const SinusoidFitter& fitter, int k) {
  const SinusoidModel& m = fitter.model();
  Eigen::MatrixXd x = fitter.residual();
  for (int n = 0; n < x.rows(); ++n) {
    const double phase = m.frequencies[k] * fitter.grid().Tau(n);
    x.row(n) += std::cos(phase) * m.cos_coefficients.row(k) + std::sin(phase) * m.sin_coefficients.row(k);
  }
  return x;
}

// How far the frequencies of line k, refined on each half of the record
// with the other lines taken out, disagree. A record whose motion drifts (an
// integrator's phase error, a slow change of a measured system) has lines
// that a joint fit makes consistent to round-off and standard errors far
// below the truth: the Kepler orbit's fundamental from CVODE, 1.2e-13
// claimed against 4e-10 off the exact a^-3/2.
double HalvesDisagreement(const SinusoidFitter& fitter, int k, const RefinementOptions& options) {
  const Eigen::MatrixXd line = IsolatedLine(fitter, k);
  const SampleGrid& whole = fitter.grid();
  const int half = whole.size / 2;
  const double f = fitter.model().frequencies[k];
  double found[2];
  for (int h = 0; h < 2; ++h) {
    const SampleGrid grid{whole.t0 + h * half * whole.dt, whole.dt, half};
    SpectrumAnalyzer analyzer(grid, Window(4));
    const Eigen::MatrixXd windowed = analyzer.weights().asDiagonal() * line.middleRows(h * half, half);
    const double bin = grid.BinWidth();
    found[h] = RefineLineFrequency(grid, windowed, analyzer.weight_sum(), f - bin, f + bin, f, options).frequency;
  }
  return std::abs(found[0] - found[1]);
}

// A base's uncertainty is at least what the halves of the record disagree
// on, when that is beyond what its statistical error lets them (10 sigma).
void WidenForDrift(const SinusoidFitter& fitter, const IdentificationOptions& options,
                   const std::vector<Component>& components, std::vector<BaseFrequency>* bases) {
  const std::vector<double>& f = fitter.model().frequencies;
  for (BaseFrequency& b : *bases) {
    if (b.known || b.line < 0) continue;
    const int k = static_cast<int>(std::find(f.begin(), f.end(), components[b.line].frequency) - f.begin());
    if (k == static_cast<int>(f.size())) continue;
    const double disagreement = HalvesDisagreement(fitter, k, options.refinement);
    if (disagreement > 10 * b.uncertainty) {
      b.drift = disagreement;
      b.uncertainty = disagreement;
    }
  }
}

}  // namespace

bool IdentificationOptions::Validate(std::string* why) const {
  auto fail = [why](const char* message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!(relative_threshold >= 0.0)) return fail("relative_threshold must be >= 0");
  if (!(noise_threshold >= 0.0)) return fail("noise_threshold must be >= 0");
  if (max_components < 1) return fail("max_components must be >= 1");
  if (!(polish_dynamic_range > 0.0 && polish_dynamic_range < 1.0)) {
    return fail("polish_dynamic_range must be in (0, 1)");
  }
  if (window_order < 0) return fail("window_order must be >= 0 (0 = automatic)");
  if (max_window_order < 1) return fail("max_window_order must be >= 1");
  if (!(lobe_separation > 0.0)) return fail("lobe_separation must be > 0");
  if (max_polish_sweeps < 1) return fail("max_polish_sweeps must be >= 1");
  if (!(polish_tolerance > 0.0)) return fail("polish_tolerance must be > 0");
  if (bases.max_bases < 1 || bases.max_bases > 3) return fail("bases.max_bases must be 1, 2 or 3");
  if (bases.max_order < 1) return fail("bases.max_order must be >= 1");
  if (static_cast<int>(bases.known_frequencies.size()) > bases.max_bases) {
    return fail("more known frequencies than bases.max_bases");
  }
  return true;
}

const char* ToString(IdentificationStatus status) {
  switch (status) {
    case IdentificationStatus::kSuccess: return "success";
    case IdentificationStatus::kUnexplainedComponents: return "unexplained_components";
    case IdentificationStatus::kNoConvergence: return "no_convergence";
    case IdentificationStatus::kNoComponents: return "no_components";
    case IdentificationStatus::kInvalidInput: return "invalid_input";
  }
  return "unknown";
}

bool IdentifyFrequencies(const IdentificationOptions& options, const Signal& signal,
                         IdentificationSummary* summary) {
  const Clock::time_point start = Clock::now();
  *summary = IdentificationSummary();
  summary->num_samples = signal.num_samples();
  summary->num_channels = signal.num_channels();
  summary->dt = signal.dt;
  summary->duration = signal.duration();
  summary->channel_names = signal.channel_names;
  std::string why;
  if (!options.Validate(&why) || !ValidateSignal(signal, kMinSamples, &why)) {
    summary->status = IdentificationStatus::kInvalidInput;
    summary->message = why;
    summary->total_seconds = SecondsSince(start);
    return false;
  }

  // 1-2. Detection, then the window order the line spacing allows.
  Identifier identifier(options, signal, summary);
  identifier.Detect();
  const SampleGrid grid{signal.t0, signal.dt, signal.num_samples()};
  summary->window_order_automatic = options.window_order == 0;
  if (summary->window_order_automatic && identifier.fitter().num_lines() > 0) {
    const double spacing = MinSpacingBins(identifier.fitter().model(), grid.BinWidth());
    const int order =
        Window::ChooseOrder(spacing, options.lobe_separation, options.max_window_order);
    if (order != identifier.window_order()) {
      identifier.SetWindow(order);
      identifier.Polish();
      identifier.Detect();
      // New lines may have narrowed the spacing: never keep a window whose
      // lobes the lines no longer fit in (no further detection, though).
      const double new_spacing = MinSpacingBins(identifier.fitter().model(), grid.BinWidth());
      const int new_order =
          Window::ChooseOrder(new_spacing, options.lobe_separation, options.max_window_order);
      if (new_order < order) {
        identifier.SetWindow(new_order);
        identifier.Polish();
      }
    }
  }
  summary->window_order = identifier.window_order();
  summary->detection_stopped_early = identifier.stopped_early();
  if (summary->detection_stopped_early) {
    summary->message =
        "detection stopped early: polishing stopped converging (is the record a sum of "
        "stationary lines?); ";
  }
  if (identifier.rounds_exhausted()) {
    summary->message += "detection ended after " + std::to_string(kRoundsPerComponent * options.max_components) +
                        " rounds (a line pruned by polishing kept coming back); ";
  }
  summary->detection_seconds = SecondsSince(start);

  SinusoidFitter& fitter = identifier.fitter();
  if (fitter.num_lines() == 0) {
    summary->status = IdentificationStatus::kNoComponents;
    summary->message = "no spectral line above the thresholds";
    summary->mean = fitter.model().mean.transpose();
    summary->residual_rms = fitter.WeightedResidualRms().transpose();
    summary->total_seconds = SecondsSince(start);
    return false;
  }
  summary->min_line_spacing_bins = MinSpacingBins(fitter.model(), grid.BinWidth());

  // 3. Final fit.
  const Clock::time_point fitting_start = Clock::now();
  identifier.Polish();
  if (!fitter.FitAllCoefficients()) {
    summary->message = "joint amplitude fit is singular (coincident lines?); kept block fits. ";
  }
  const PolishOptions polish = identifier.MakePolishOptions(options.polish_tolerance);
  std::vector<double> errors = fitter.FrequencyStandardErrors(polish.cluster_spacing);
  summary->fitting_seconds = SecondsSince(fitting_start);

  const SinusoidModel& model = fitter.model();
  const int lines = model.num_lines();
  const int channels = signal.num_channels();
  const double center = grid.Center();
  std::vector<Component> components(lines);
  for (int k = 0; k < lines; ++k) {
    Component& c = components[k];
    c.frequency = model.frequencies[k];
    // Below a few ulps the statistical estimate is meaningless.
    c.frequency_uncertainty =
        std::max(errors[k], 4.0 * std::numeric_limits<double>::epsilon() * c.frequency);
    c.amplitude.resize(channels);
    c.phase.resize(channels);
    for (int ch = 0; ch < channels; ++ch) {
      const double a = model.cos_coefficients(k, ch);
      const double b = model.sin_coefficients(k, ch);
      c.amplitude(ch) = std::hypot(a, b);
      // a cos(w tau) + b sin(w tau) = A cos(w tau + p), p = atan2(-b, a), and
      // tau = t - center.
      c.phase(ch) = WrapPhase(std::atan2(-b, a) - c.frequency * center);
    }
    c.amplitude_norm = c.amplitude.norm();
  }
  std::stable_sort(components.begin(), components.end(),
                   [](const Component& a, const Component& b) {
                     return a.amplitude_norm > b.amplitude_norm;
                   });
  summary->mean = model.mean.transpose();
  summary->residual_rms = fitter.WeightedResidualRms().transpose();

  // 4. Bases.
  const Clock::time_point bases_start = Clock::now();
  std::vector<LineEstimate> estimates(lines);
  for (int k = 0; k < lines; ++k) {
    estimates[k] = {components[k].frequency, components[k].frequency_uncertainty,
                    0.5 * components[k].amplitude_norm * components[k].amplitude_norm};
  }
  BaseSelection selection;
  if (!SelectBases(estimates, options.bases, &selection)) {
    summary->status = IdentificationStatus::kInvalidInput;
    summary->message += selection.message;
    summary->components = std::move(components);
    summary->total_seconds = SecondsSince(start);
    return false;
  }
  for (int k = 0; k < lines; ++k) {
    components[k].label = selection.labels[k];
    components[k].lattice_residual = selection.lattice_residuals[k];
  }
  summary->bases = selection.bases;
  WidenForDrift(fitter, options, components, &summary->bases);
  summary->components = std::move(components);
  summary->num_explained = selection.num_explained;
  summary->explained_energy_fraction = selection.explained_energy_fraction;
  summary->num_candidate_bases_tried = selection.num_candidate_bases_tried;
  summary->base_selection_seconds = SecondsSince(bases_start);
  summary->status = selection.num_explained == lines ? IdentificationStatus::kSuccess
                                                     : IdentificationStatus::kUnexplainedComponents;
  summary->message += selection.message;
  if (!summary->polish_converged) {
    summary->message += "; final polish did not converge";
    summary->status = IdentificationStatus::kNoConvergence;
  }
  if (summary->detection_stopped_early) summary->status = IdentificationStatus::kNoConvergence;
  summary->total_seconds = SecondsSince(start);
  return summary->IsUsable();
}

namespace {

std::string Format(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

std::string LabelString(const std::vector<int>& label) {
  if (label.empty()) return "-";
  std::ostringstream os;
  os << "(";
  for (std::size_t i = 0; i < label.size(); ++i) os << (i ? "," : "") << label[i];
  os << ")";
  return os.str();
}

}  // namespace

std::string IdentificationSummary::BriefReport() const {
  std::ostringstream os;
  os << "Frequency identification: " << ToString(status) << ", ";
  if (status == IdentificationStatus::kInvalidInput) {
    os << message;
    return os.str();
  }
  os << bases.size() << (bases.size() == 1 ? " base" : " bases");
  if (!bases.empty()) {
    os << " (";
    for (std::size_t i = 0; i < bases.size(); ++i) {
      os << (i ? ", " : "") << Format("%.15g", bases[i].frequency);
    }
    os << ")";
  }
  os << ", " << num_explained << "/" << components.size() << " components explained, window Hann^"
     << window_order << ", " << Format("%.3g", total_seconds) << " s";
  return os.str();
}

std::string IdentificationSummary::FullReport() const {
  std::ostringstream os;
  os << "Frequency identification report\n";
  os << "  status                " << ToString(status) << (message.empty() ? "" : ": ") << message
     << "\n";
  os << "  record                " << num_samples << " samples x " << num_channels
     << " channels, dt " << Format("%.6g", dt) << ", T " << Format("%.6g", duration) << " (bin "
     << Format("%.4g", duration > 0 ? 2.0 * kPi / duration : 0.0) << " rad/unit)\n";
  os << "  window                Hann^" << window_order
     << (window_order_automatic ? " (automatic)" : " (forced)") << ", min line spacing "
     << Format("%.4g", min_line_spacing_bins) << " bins\n";
  os << "  refinement            " << line_refinements << " line refinements ("
     << refinement_evaluations << " |phi|^2 evaluations), " << num_polishes << " polishes ("
     << polish_sweeps << " sweeps, largest block " << largest_cluster << ", "
     << pruned_lines << " lines pruned, final "
     << (polish_converged ? "converged" : "NOT converged") << " at "
     << Format("%.2g", polish_last_change) << ")\n";
  os << "  explained             " << num_explained << " of " << components.size()
     << " components, " << Format("%.12g", 100.0 * explained_energy_fraction)
     << "% of the energy (" << num_candidate_bases_tried << " candidate bases tried)\n";
  for (int c = 0; c < residual_rms.size(); ++c) {
    const std::string name =
        c < static_cast<int>(channel_names.size()) ? channel_names[c] : "x" + std::to_string(c);
    os << "  channel " << name << ": mean " << Format("%.6g", mean(c)) << ", residual rms "
       << Format("%.3g", residual_rms(c)) << "\n";
  }
  os << "  bases\n";
  for (std::size_t i = 0; i < bases.size(); ++i) {
    os << "    w" << i + 1 << " = " << Format("%.16g", bases[i].frequency) << " +- "
       << Format("%.2g", bases[i].uncertainty) << (bases[i].known ? "  [known]" : "")
       << (bases[i].drift > 0 ? "  (the record's halves disagree by " + Format("%.2g", bases[i].drift) + ")" : "")
       << (bases[i].line >= 0 ? "  (component #" + std::to_string(bases[i].line) + ")" : "")
       << "\n";
  }
  os << "  components (amplitude and phase of channel 0; phase at t = 0)\n";
  os << "      #  frequency               +-        label        amplitude    phase     "
        "lattice residual\n";
  for (std::size_t k = 0; k < components.size(); ++k) {
    const Component& c = components[k];
    char line[256];
    // An unlabelled line has no lattice point: "-", never a printed NaN.
    const std::string residual =
        std::isfinite(c.lattice_residual) ? Format("%.2g", c.lattice_residual) : std::string("-");
    std::snprintf(line, sizeof(line), "  %5zu  %-22.16g  %-8.2g  %-11s  %-11.4e  %-+8.4f  %s\n",
                  k, c.frequency, c.frequency_uncertainty, LabelString(c.label).c_str(),
                  c.amplitude.size() ? c.amplitude(0) : 0.0, c.phase.size() ? c.phase(0) : 0.0,
                  residual.c_str());
    os << line;
  }
  os << "  time                  detection " << Format("%.3g", detection_seconds) << " s, fit "
     << Format("%.3g", fitting_seconds) << " s, bases " << Format("%.3g", base_selection_seconds)
     << " s, total " << Format("%.3g", total_seconds) << " s\n";
  return os.str();
}

}  // namespace rmhb::frequency_id
