#include "rmhb/truncation_estimate.h"

#include <algorithm>
#include <cmath>
#include <set>

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

// Ratio of sizes per level from a least-squares line through the log of the
// running-maximum envelope over the upper half of the levels.
double FitDecay(const HarmonicBasis& basis, const std::vector<double>& size, int top) {
  std::vector<double> envelope(top + 1, 0.0);
  for (int k = 1; k < basis.size(); ++k) {
    const int l = Level(basis.harmonic(k));
    envelope[l] = std::max(envelope[l], size[k]);
  }
  for (int l = top - 1; l >= 0; --l) envelope[l] = std::max(envelope[l], envelope[l + 1]);
  // Top levels at round-off are a parity's empty layer (the Duffing's even
  // harmonics at an even order), not the decay: left out of the fit.
  int last = top;
  while (last > 1 && !(envelope[last] > 1e-14)) --last;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, n = 0;
  for (int l = std::max(1, top / 2); l <= last; ++l) {
    if (!(envelope[l] > 0)) continue;
    const double y = std::log(envelope[l]);
    sx += l, sy += y, sxx += double(l) * l, sxy += l * y, n += 1;
  }
  const double slope = n >= 2 ? (n * sxy - sx * sy) / (n * sxx - sx * sx) : 0;
  return slope < -1e-3 ? std::exp(slope) : 1.0;
}

double Tail(const HarmonicSolution& s, double* decay, int* top) {
  const std::vector<double> size = HarmonicSizes(s);
  *top = 0;
  for (const auto& k : s.basis().harmonics()) *top = std::max(*top, Level(k));
  *decay = FitDecay(s.basis(), size, *top);
  // Sum of the boundary layer times the geometric series of what lies
  // beyond it (at least once: the first neglected layer feeds back into the
  // retained coefficients at about its own size).
  const double r = std::min(*decay, 0.95);
  double boundary = 0;
  for (int k : Boundary(s.basis())) boundary += size[k];
  return boundary * std::max(1.0, r / (1 - r));
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

int TruncationEstimate::PredictLevel(double target) const {
  if (state <= target) return top_level;
  if (!(decay < 1)) return -1;
  return top_level + static_cast<int>(std::ceil(std::log(target / state) / std::log(decay)));
}

TruncationEstimate EstimateTruncation(const HarmonicSolution& s, const HarmonicSolution* lower) {
  TruncationEstimate e;
  e.tail = Tail(s, &e.decay, &e.top_level);
  e.state = e.frequency = e.tail;
  if (!lower) return e;
  double lower_decay = 1;
  int lower_top = 0;
  const double lower_tail = Tail(*lower, &lower_decay, &lower_top);
  // Both at round-off: nothing to calibrate against.
  if (!(lower_tail > 1e-13)) return e;
  const Eigen::MatrixXd& c = s.coefficients();
  const Eigen::MatrixXd d = lower->OnBasis(s.basis()).coefficients() - c;
  const std::vector<double> scale = VariableScales(c);
  double state = 0;
  for (int j = 0; j < c.rows(); ++j) {
    double sum = 0;
    for (int k = 0; k < s.basis().size(); ++k) sum += Magnitude(d, j, k);
    state = std::max(state, sum / scale[j]);
  }
  double frequency = 0;
  for (size_t b = 0; b < s.frequencies().size(); ++b)
    frequency = std::max(frequency, std::abs(lower->frequencies()[b] - s.frequencies()[b]) / std::abs(s.frequencies()[b]));
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

}  // namespace rmhb
