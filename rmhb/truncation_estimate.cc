#include "rmhb/truncation_estimate.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "rmhb/sampling.h"
#include "rmhb/spectral_transform.h"

namespace rmhb {
namespace {

std::vector<double> VariableScales(const Eigen::MatrixXd& c) {
  const double global = c.size() ? c.cwiseAbs().maxCoeff() : 0.0;
  std::vector<double> scale(c.rows());
  for (int j = 0; j < c.rows(); ++j)
    scale[j] = std::max({c.row(j).cwiseAbs().maxCoeff(), 1e-6 * global, 1e-300});
  return scale;
}

double Magnitude(const Eigen::MatrixXd& c, int j, int k) {
  return k == 0 ? std::abs(c(j, 0)) : std::hypot(c(j, 2 * k - 1), c(j, 2 * k));
}

int Level(const std::vector<int>& k) {
  int l = 0;
  for (int m : k) l += std::abs(m);
  return l;
}

// Harmonics with a neighbour k + d (|d|_1 <= 2, k + d != 0) outside the
// basis: where the truncation cuts the spectrum. Two steps, so that a
// spectrum with only every other harmonic (a half-wave symmetry) still has
// its last non-zero layer on the boundary.
std::vector<int> Boundary(const HarmonicBasis& basis) {
  const int d = basis.num_bases();
  std::vector<int> out;
  if (d == 1) {
    for (int k = 1; k < basis.size(); ++k)
      if (basis.harmonic(k)[0] >= basis.order() - 1) out.push_back(k);
    return out;
  }
  std::set<std::vector<int>> in;
  for (const auto& k : basis.harmonics()) {
    in.insert(k);
    std::vector<int> neg(k);
    for (int& v : neg) v = -v;
    in.insert(neg);
  }
  const std::vector<std::vector<int>> steps = NeighbourSteps(d);
  for (int k = 1; k < basis.size(); ++k)
    for (const auto& s : steps) {
      std::vector<int> n = basis.harmonic(k);
      bool zero = true;
      for (int i = 0; i < d; ++i) n[i] += s[i], zero = zero && n[i] == 0;
      if (!zero && !in.count(n)) {
        out.push_back(k);
        break;
      }
    }
  return out;
}

// The largest size per level |k|_1 (level 0 left empty).
std::vector<double> LevelSizes(const HarmonicBasis& basis, const std::vector<double>& size, int top) {
  std::vector<double> level(top + 1, 0.0);
  for (int k = 1; k < basis.size(); ++k) {
    const int l = Level(basis.harmonic(k));
    level[l] = std::max(level[l], size[k]);
  }
  return level;
}

// The slope of a least-squares line through the log of the running-maximum
// envelope of the level sizes over the upper half of the levels, against the
// level (geometric decay) or its log (algebraic).
double FitSlope(const std::vector<double>& level, DecayModel model) {
  const int top = static_cast<int>(level.size()) - 1;
  std::vector<double> envelope(level);
  for (int l = top - 1; l >= 0; --l) envelope[l] = std::max(envelope[l], envelope[l + 1]);
  // Top levels at round-off are a parity's empty layer (the Duffing's even
  // harmonics at an even order), not the decay: left out of the fit.
  int last = top;
  while (last > 1 && !(envelope[last] > 1e-14)) --last;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (int l = std::max(1, top / 2); l <= last; ++l) {
    if (!(envelope[l] > 0)) continue;
    const double x = model == DecayModel::kAlgebraic ? std::log(double(l)) : double(l);
    const double y = std::log(envelope[l]);
    sx += x, sy += y, sxx += x * x, sxy += x * y, n += 1;
  }
  return n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0;
}

// Algebraic decay, sizes ~ C l^-p: a kink's spectrum oscillates under that
// law (|c_k| ~ k^-p |sin(k theta)|, theta where the kinks fall), so the
// boundary may sit at a node (NLvib's example 03 at N = 100: its boundary
// 4x below its neighbours'). C is the upper envelope over the upper half of
// the levels, max size(l) l^p, and the neglected part is the sum over
// l > N of C l^-p ~ C N^(1 - p) / (p - 1), at least one level's C N^-p.
double AlgebraicTail(const std::vector<double>& level, double p) {
  const int top = static_cast<int>(level.size()) - 1;
  double c = 0;
  for (int l = std::max(1, top / 2); l <= top; ++l) c = std::max(c, level[l] * std::pow(double(l), p));
  const double at_top = c * std::pow(double(top), -p);
  return at_top * std::max(1.0, top / (p - 1));
}

// max_t |x_j(t)| per row of one base's coefficients c, on 8 samples per
// harmonic (the sum of |c_jk| would count the lower solution's neglected
// harmonics whole: for an algebraic decay it is their sum, several times the
// time-domain difference the calibration is after).
Eigen::VectorXd LargestInTime(const HarmonicBasis& basis, const Eigen::MatrixXd& c) {
  SpectralTransform transform(basis, Sampling::Uniform(FftFriendlySize(8 * basis.order() + 1)));
  std::vector<double> row(c.cols()), samples(transform.num_samples());
  Eigen::VectorXd out(c.rows());
  for (int j = 0; j < c.rows(); ++j) {
    for (int i = 0; i < c.cols(); ++i) row[i] = c(j, i);
    transform.Synthesize(row.data(), samples.data());
    double m = 0;
    for (double v : samples) m = std::max(m, std::abs(v));
    out(j) = m;
  }
  return out;
}

// The neglected harmonics' summed size, relative (METHOD.md s.8 and s.15).
// Geometric, ratio r per level: the boundary's summed size times the series
// r / (1 - r), at least once (the first neglected layer feeds back into the
// retained coefficients at about its own size). Algebraic: AlgebraicTail
// with the fitted exponent, or `exponent` when given (> 0); a barely
// decaying spectrum (p < 1.5) trusts no decay: N times the boundary.
double Tail(const HarmonicSolution& s, DecayModel model, TruncationEstimate* e, double exponent = 0) {
  const std::vector<double> size = HarmonicSizes(s);
  e->top_level = 0;
  for (const auto& k : s.basis().harmonics()) e->top_level = std::max(e->top_level, Level(k));
  const std::vector<double> level = LevelSizes(s.basis(), size, e->top_level);
  const double slope = FitSlope(level, model);
  double boundary = 0;
  for (int k : Boundary(s.basis())) boundary += size[k];
  if (model == DecayModel::kAlgebraic) {
    e->exponent = exponent > 0 ? exponent : -slope >= 1.5 ? -slope : 0;
    return e->exponent > 0 ? std::max(boundary, AlgebraicTail(level, e->exponent))
                           : boundary * std::max(1, e->top_level);
  }
  e->decay = slope < -1e-3 ? std::exp(slope) : 1.0;
  const double r = std::min(e->decay, 0.95);
  return boundary * std::max(1.0, r / (1 - r));
}

// Algebraic calibration (METHOD.md s.15). A low order's spectrum still falls
// faster than its asymptotic law (a contact oscillator fitted p = 5.6 at
// N = 25 where its errors fall like N^-2.5; p = 1.7 at N = 12), so the
// exponent is the smaller of the two solutions' fits, both tails taken with
// it. The estimate is the larger of the calibrated tail, the constant being
// 1.25 times the difference over the lower tail (the difference is
// 1 - 2^(1 - p) of the lower solution's error at the ladder's steps of 2x,
// 0.78 for example 03's N^-2.2, which the 1.25 restores; at least
// 0.1: the tail sums every neglected harmonic, whose time-domain maximum is
// below that sum, ~0.3 of it on NLvib's example 03), and the difference
// extrapolated: errors ~ N^(1 - p) make this solution's error r / (1 - r)
// times it, r = (N_lower / N)^(p - 1) (without a decay, the difference).
void CalibrateAlgebraic(const HarmonicSolution& s, const HarmonicSolution& lower, TruncationEstimate* e) {
  TruncationEstimate lower_fit;
  Tail(lower, DecayModel::kAlgebraic, &lower_fit);
  const double p = lower_fit.exponent > 0 && e->exponent > 0 ? std::min(lower_fit.exponent, e->exponent) : 0;
  e->tail = Tail(s, DecayModel::kAlgebraic, e, p);
  const double lower_tail = Tail(lower, DecayModel::kAlgebraic, &lower_fit, p);
  if (!(lower_tail > 1e-13)) return;
  const double difference = StateDifference(s, lower, DecayModel::kAlgebraic);
  // Without a decay, or with no higher level (an index set grown within its
  // reach), the difference itself (r = 1/2).
  const double r = p > 0 && lower_fit.top_level < e->top_level
                       ? std::pow(double(lower_fit.top_level) / e->top_level, p - 1)
                       : 0.5;
  constexpr double kSafety = 1.25;
  const double calibrated = std::max(0.1, kSafety * difference / lower_tail) * e->tail;
  e->state = std::max(calibrated, kSafety * difference * r / (1 - r));
  const double frequency = FrequencyDifference(s, lower);
  e->frequency = std::min(e->state, kSafety * frequency * std::max(e->tail / lower_tail, r / (1 - r)));
  e->calibrated = true;
}

}  // namespace

std::vector<std::vector<int>> NeighbourSteps(int d) {
  std::vector<std::vector<int>> steps;
  for (int i = 0; i < d; ++i)
    for (int a : {-2, -1, 1, 2}) {
      std::vector<int> s(d, 0);
      s[i] = a;
      steps.push_back(s);
      if (std::abs(a) != 1) continue;
      for (int j = i + 1; j < d; ++j)
        for (int b : {-1, 1}) {
          std::vector<int> t = s;
          t[j] = b;
          steps.push_back(t);
        }
    }
  return steps;
}

std::vector<double> HarmonicSizes(const HarmonicSolution& s) {
  const Eigen::MatrixXd& c = s.coefficients();
  const std::vector<double> scale = VariableScales(c);
  std::vector<double> size(s.basis().size(), 0.0);
  for (int j = 0; j < c.rows(); ++j)
    for (int k = 0; k < s.basis().size(); ++k) size[k] = std::max(size[k], Magnitude(c, j, k) / scale[j]);
  return size;
}

double FrequencyDifference(const HarmonicSolution& s, const HarmonicSolution& other) {
  double largest = 0;
  for (size_t b = 0; b < s.frequencies().size(); ++b)
    largest = std::max(largest, std::abs(other.frequencies()[b] - s.frequencies()[b]) / std::abs(s.frequencies()[b]));
  return largest;
}

double StateDifference(const HarmonicSolution& s, const HarmonicSolution& other, DecayModel model) {
  const Eigen::MatrixXd& c = s.coefficients();
  const Eigen::MatrixXd d = other.OnBasis(s.basis()).coefficients() - c;
  const std::vector<double> scale = VariableScales(c);
  const bool in_time = model == DecayModel::kAlgebraic && s.basis().num_bases() == 1;
  const Eigen::VectorXd largest = in_time ? LargestInTime(s.basis(), d) : Eigen::VectorXd();
  double state = 0;
  for (int j = 0; j < c.rows(); ++j) {
    double difference = in_time ? largest(j) : 0;
    for (int k = 0; !in_time && k < s.basis().size(); ++k) difference += Magnitude(d, j, k);
    state = std::max(state, difference / scale[j]);
  }
  return state;
}

int TruncationEstimate::PredictLevel(double target) const {
  if (state <= target) return top_level;
  if (model == DecayModel::kAlgebraic) {
    // The state error ~ N^(1 - p): the tail of the sum of l^-p.
    if (!(exponent > 0)) return -1;
    return static_cast<int>(std::ceil(top_level * std::pow(state / target, 1 / (exponent - 1))));
  }
  if (!(decay < 1)) return -1;
  return top_level + static_cast<int>(std::ceil(std::log(target / state) / std::log(decay)));
}

TruncationEstimate EstimateTruncation(const HarmonicSolution& s, const HarmonicSolution* lower, DecayModel model) {
  TruncationEstimate e;
  e.model = model;
  e.tail = Tail(s, model, &e);
  e.state = e.frequency = e.tail;
  if (!lower) return e;
  if (model == DecayModel::kAlgebraic) {
    CalibrateAlgebraic(s, *lower, &e);
    return e;
  }
  TruncationEstimate lower_fit;
  const double lower_tail = Tail(*lower, model, &lower_fit);
  // Both at round-off: nothing to calibrate against.
  if (!(lower_tail > 1e-13)) return e;
  const double state = StateDifference(s, *lower, model);
  const double frequency = FrequencyDifference(s, *lower);
  e.calibrated = true;
  // The lower solution's error is its difference from this one (this one
  // being far closer): the constant is that error over its tail, taken
  // twice (the difference misses this solution's own error, and errors and
  // tails do not scale exactly alike: 1.0e-12 measured where once gave
  // 9.9e-13 on an exponential restoring force).
  constexpr double kSafety = 2;
  e.state = std::max(1.0, kSafety * state / lower_tail) * e.tail;
  e.frequency = std::min(e.state, kSafety * frequency / lower_tail * e.tail);
  return e;
}

double NeutralBand(const HarmonicSolution& s, double band, bool* widened) {
  const double from_orbit = kMultiplierErrorPerTruncation * EstimateTruncation(s).state;
  if (widened) *widened = from_orbit > band;
  return std::max(band, from_orbit);
}

}  // namespace rmhb
