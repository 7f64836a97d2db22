#ifndef RMHB_HARMONIC_BASIS_H_
#define RMHB_HARMONIC_BASIS_H_

// The truncated Fourier basis: a set of harmonics k (integer vectors over the
// base frequencies w), each contributing cos(k.w t) and sin(k.w t). Only one
// of k, -k is kept (first non-zero entry positive), so every frequency
// appears once. Coefficient layout per variable:
//   [a_0, a_1, b_1, ..., a_{K-1}, b_{K-1}]
// with harmonic 0 first: 2K - 1 numbers.

#include <memory>
#include <string>
#include <vector>

namespace rmhb {

class HarmonicBasis {
 public:
  // k = 0, 1, ..., order: the classical periodic basis.
  static HarmonicBasis Periodic(int order);
  // |k_1| + ... + |k_d| <= order (the paper's RMHB index set).
  static HarmonicBasis Diamond(int num_bases, int order);
  // max |k_i| <= order.
  static HarmonicBasis Box(int num_bases, int order);
  // sum_i weight_i |k_i| <= order: a diamond stretched along the bases whose
  // harmonics decay slowly (weight 1) and squeezed along those whose decay
  // fast (weight > 1), e.g. a weakly forced limit cycle: its own harmonics
  // fall by ~5 per step, the forcing's combination tones by ~100.
  static HarmonicBasis WeightedDiamond(const std::vector<int>& weights, int order);
  // An explicit index set, for spectra that no standard shape covers
  // economically: a fast oscillation modulated by a slow beat has harmonics
  // m w1 + n w2 spread far along the slow direction (n, -n) and few along the
  // fast one, so the diamond or box that reaches them is mostly empty. Either
  // sign of each k may be given; duplicates and zero are dropped, and zero is
  // always harmonic 0. `order` is the caller's label for the set (what order
  // continuation and reports show); `shape` names it.
  static HarmonicBasis FromHarmonics(int num_bases, std::vector<std::vector<int>> harmonics,
                                     int order, std::string shape);

  int num_bases() const { return num_bases_; }
  int size() const { return static_cast<int>(harmonics_->size()); }  // K, with k = 0
  int num_coefficients() const { return 2 * size() - 1; }
  int order() const { return order_; }
  const std::string& shape() const { return shape_; }
  const std::vector<int>& harmonic(int k) const { return (*harmonics_)[k]; }
  const std::vector<std::vector<int>>& harmonics() const { return *harmonics_; }
  // Largest |k_base| in the set: what the alias bound needs per base.
  int Reach(int base) const;
  // Index of a harmonic in the set (either sign), or -1.
  int Find(const std::vector<int>& k) const;

  // Angular frequency k.w of harmonic index k.
  double Frequency(int k, const std::vector<double>& w) const;

 private:
  HarmonicBasis(int num_bases, int order, std::string shape)
      : num_bases_(num_bases), order_(order), shape_(std::move(shape)) {}
  int num_bases_;
  int order_;
  std::string shape_;
  // Filled by the factories, never changed after: copies share it (a solve
  // copies its basis into every residual, transform and solution; one
  // allocation per harmonic per copy was most of a small solve's malloc).
  std::shared_ptr<std::vector<std::vector<int>>> harmonics_ =
      std::make_shared<std::vector<std::vector<int>>>();
};

}  // namespace rmhb

#endif  // RMHB_HARMONIC_BASIS_H_
