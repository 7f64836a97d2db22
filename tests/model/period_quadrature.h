#ifndef RMHB_TESTS_MODEL_PERIOD_QUADRATURE_H_
#define RMHB_TESTS_MODEL_PERIOD_QUADRATURE_H_

// Independent references for the solve tests: the exact period of a
// conservative oscillator x'' + f(x) = 0 by quadrature, in long double.
//
// Released at rest from x_max, x oscillates between x_min and x_max with
// V(x_min) = V(x_max), V' = f, and
//   T = 2 * integral_{x_min}^{x_max} dx / sqrt(2 (E - V(x))).
// The endpoint singularities are removed with x = mid + half sin(phi), and
// E - V(x) is computed as (x_max - x) * mean of f over [x, x_max] (upper
// half, lower half symmetric) so that no cancellation occurs near the turning
// points: the integrand becomes sqrt(half (1 + sin phi) / (2 mean)), analytic
// on each half, and Gauss-Legendre converges exponentially.

#include <cmath>
#include <functional>
#include <vector>

namespace rmhb::testing {

using Real = long double;

class GaussLegendre {
 public:
  explicit GaussLegendre(int n) : x_(n), w_(n) {
    const Real pi = 3.141592653589793238462643383279502884L;
    for (int i = 0; i < n; ++i) {
      Real z = std::cos(pi * (i + 0.75L) / (n + 0.5L));
      Real dp = 0;
      for (int it = 0; it < 100; ++it) {
        Real p0 = 1, p1 = z;
        for (int k = 2; k <= n; ++k) {
          const Real p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = n * (z * p1 - p0) / (z * z - 1);
        const Real step = p1 / dp;
        z -= step;
        if (std::fabs(step) < 1e-21L) break;
      }
      x_[i] = z;
      w_[i] = 2 / ((1 - z * z) * dp * dp);
    }
  }
  // integral of f over [a, b]
  Real Integrate(const std::function<Real(Real)>& f, Real a, Real b) const {
    const Real mid = (a + b) / 2, half = (b - a) / 2;
    Real s = 0;
    for (std::size_t i = 0; i < x_.size(); ++i) s += w_[i] * f(mid + half * x_[i]);
    return s * half;
  }

 private:
  std::vector<Real> x_, w_;
};

struct Oscillation {
  Real period = 0;
  Real x_min = 0;
  Real omega() const { return 2 * 3.141592653589793238462643383279502884L / period; }
};

// f must be restoring (f(x) x > 0 for x != 0) between x_min and x_max > 0.
inline Oscillation ConservativeOscillation(const std::function<Real(Real)>& f, Real x_max) {
  static const GaussLegendre rule(96);
  // x_min < 0 with integral_{x_min}^{x_max} f = 0 (Newton).
  Real xm = -x_max;
  for (int it = 0; it < 100; ++it) {
    const Real g = rule.Integrate(f, xm, x_max);
    const Real step = g / -f(xm);
    xm -= step;
    if (std::fabs(step) < 1e-20L) break;
  }
  const Real mid = (x_max + xm) / 2, half = (x_max - xm) / 2;
  auto upper = [&](Real phi) {
    const Real x = mid + half * std::sin(phi);
    const Real mean = rule.Integrate(f, x, x_max) / (x_max - x);
    return std::sqrt(half * (1 + std::sin(phi)) / (2 * mean));
  };
  auto lower = [&](Real phi) {
    const Real x = mid + half * std::sin(phi);
    const Real mean = -rule.Integrate(f, xm, x) / (x - xm);
    return std::sqrt(half * (1 - std::sin(phi)) / (2 * mean));
  };
  const Real pi = 3.141592653589793238462643383279502884L;
  Oscillation o;
  o.period = 2 * (rule.Integrate(upper, 0, pi / 2) + rule.Integrate(lower, -pi / 2, 0));
  o.x_min = xm;
  return o;
}

}  // namespace rmhb::testing

#endif  // RMHB_TESTS_MODEL_PERIOD_QUADRATURE_H_
