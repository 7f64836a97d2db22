#ifndef RMHB_FREQUENCY_ID_WINDOW_H_
#define RMHB_FREQUENCY_ID_WINDOW_H_

#include <Eigen/Core>

namespace rmhb::frequency_id {

// The Hann-power ("higher-order cosine") window of order q >= 1,
//
//   W_q(s) = (1 - cos 2 pi s)^q * 2^q / binom(2q, q),   s = t / T in [0, 1],
//
// scaled to unit mean. W_q and its first 2q-1 derivatives vanish at both
// ends, which is what makes the plain trapezoid sum over the samples a
// spectrally accurate quadrature for the windowed Fourier integral, and what
// makes the leakage of a line decay like (distance)^-(2q+1): Laskar's
// frequency error falls like T^-(2q+2). The price is a main lobe of
// half-width q+1 bins, so close lines call for a low order.
class Window {
 public:
  explicit Window(int order = 1);

  int order() const { return order_; }

  // W_q(s) for s in [0, 1].
  double operator()(double s) const;

  // Samples W_q(n / (size-1)), n = 0 .. size-1: both end samples are zero.
  Eigen::VectorXd Sample(int size) const;

  // Half-width of the main lobe of the window's transform, in DFT bins.
  double MainLobeHalfWidthBins() const { return order_ + 1.0; }

  // The highest order whose main lobes still keep lines `min_spacing_bins`
  // apart separated by `lobe_separation` half-widths, i.e. the largest q
  // with min_spacing_bins >= lobe_separation * (q + 1), clamped to
  // [1, max_order].
  static int ChooseOrder(double min_spacing_bins, double lobe_separation, int max_order);

 private:
  int order_;
  double scale_;
};

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_WINDOW_H_
