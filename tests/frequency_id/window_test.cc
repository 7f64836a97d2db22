#include "frequency_id/window.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

namespace rmhb::frequency_id {
namespace {

TEST(Window, HannPowerHasUnitMeanAndVanishingEnds) {
  for (int order = 1; order <= 6; ++order) {
    const Window window(order);
    const int size = 1001;
    const Eigen::VectorXd w = window.Sample(size);
    EXPECT_EQ(w(0), 0.0);
    EXPECT_EQ(w(size - 1), 0.0);
    // A trigonometric polynomial of degree q sampled over one period: the
    // sum of the size-1 periodic samples is exact.
    EXPECT_NEAR(w.sum() / (size - 1), 1.0, 1e-13) << "order " << order;
    for (int n = 0; n < size; ++n) EXPECT_EQ(w(n), w(size - 1 - n));
    // Peak value at the centre: 2^q / binom(2q, q) * 2^q.
    double binomial = 1.0;
    for (int k = 1; k <= order; ++k) binomial = binomial * (order + k) / k;
    EXPECT_NEAR(w(size / 2), std::pow(4.0, order) / binomial, 1e-12);
  }
}

TEST(Window, HannIsOneMinusCosine) {
  const Window hann(1);
  for (double s : {0.0, 0.1, 0.25, 0.5, 0.9}) {
    EXPECT_NEAR(hann(s), 1.0 - std::cos(2.0 * M_PI * s), 1e-15);
  }
  EXPECT_DOUBLE_EQ(hann.MainLobeHalfWidthBins(), 2.0);
  EXPECT_DOUBLE_EQ(Window(4).MainLobeHalfWidthBins(), 5.0);
}

TEST(Window, HigherOrderIsSmootherAtTheEnds) {
  // Near s = 0, W_q ~ (2 pi^2 s^2)^q: each order adds two vanishing derivatives.
  const double s = 1e-2;
  EXPECT_GT(Window(1)(s), 10.0 * Window(2)(s));
  EXPECT_GT(Window(2)(s), 10.0 * Window(3)(s));
}

TEST(Window, ChooseOrderFromLineSpacing) {
  // spacing >= lobe_separation * (q + 1) bins.
  EXPECT_EQ(Window::ChooseOrder(16.0, 2.0, 4), 4);
  EXPECT_EQ(Window::ChooseOrder(16.0, 2.0, 10), 7);
  EXPECT_EQ(Window::ChooseOrder(6.0, 2.0, 4), 2);
  EXPECT_EQ(Window::ChooseOrder(5.9, 2.0, 4), 1);
  EXPECT_EQ(Window::ChooseOrder(1.27, 2.0, 4), 1);
  EXPECT_EQ(Window::ChooseOrder(0.0, 2.0, 4), 1);
  EXPECT_EQ(Window::ChooseOrder(INFINITY, 2.0, 4), 4);
}

TEST(Window, RejectsOrderZero) { EXPECT_THROW(Window(0), std::invalid_argument); }

}  // namespace
}  // namespace rmhb::frequency_id
