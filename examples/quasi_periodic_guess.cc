#include "examples/quasi_periodic_guess.h"

#include <cmath>
#include <complex>
#include <stdexcept>

namespace rmhb::examples {
namespace {

void Rk4(const std::function<void(double, const double*, double*)>& f, double t, double h,
         Eigen::VectorXd* y, Eigen::VectorXd* k1, Eigen::VectorXd* k2, Eigen::VectorXd* k3,
         Eigen::VectorXd* k4, Eigen::VectorXd* tmp) {
  f(t, y->data(), k1->data());
  *tmp = *y + 0.5 * h * *k1;
  f(t + 0.5 * h, tmp->data(), k2->data());
  *tmp = *y + 0.5 * h * *k2;
  f(t + 0.5 * h, tmp->data(), k3->data());
  *tmp = *y + h * *k3;
  f(t + h, tmp->data(), k4->data());
  *y += h / 6.0 * (*k1 + 2 * *k2 + 2 * *k3 + *k4);
}

// |sum_s hann_s z_s exp(-i w t_s)| over the first hann.size() samples: the
// windowed spectrum at w. Hann side lobes fall as 1/distance^3, so a peak a
// few bins from a stronger one is still measured cleanly. exp(-i w t) by
// recurrence.
double HannAmplitude(const Eigen::VectorXd& z, const Eigen::VectorXd& hann, double t0, double dt,
                     double w) {
  std::complex<double> rot = std::polar(1.0, -w * dt), e = std::polar(1.0, -w * t0), s = 0;
  for (long i = 0; i < hann.size(); ++i) {
    s += hann(i) * z(i) * e;
    e *= rot;
    if (i % 256 == 255) e /= std::abs(e);  // keep the recurrence on the unit circle
  }
  return std::abs(s);
}

// Strongest peak in [low, high]. A scan of the whole band at full resolution
// costs (band / resolution) x samples, so: scan on the first quarter of the
// window (4x coarser, 4x fewer samples), rescan the neighbourhood of its
// peak with the whole window, then golden-section refinement of the top.
double PeakFrequency(const Eigen::VectorXd& z, double t0, double dt, double low, double high) {
  const long all = z.size(), quarter = std::max<long>(all / 4, 16);
  auto window = [](long count) {
    Eigen::VectorXd h(count);
    for (long i = 0; i < count; ++i) h(i) = 1 - std::cos(2 * M_PI * i / (count - 1));
    return h;
  };
  const Eigen::VectorXd hann_quarter = window(quarter), hann = window(all);
  auto scan = [&](const Eigen::VectorXd& h, double from, double to, double step) {
    double best = -1, at = from;
    for (double w = from; w <= to; w += step) {
      const double a = HannAmplitude(z, h, t0, dt, w);
      if (a > best) best = a, at = w;
    }
    return at;
  };
  const double coarse = 2 * M_PI / (dt * (quarter - 1)), fine = 2 * M_PI / (dt * (all - 1));
  const double w_coarse = scan(hann_quarter, low, high, 0.25 * coarse);
  const double w_fine = scan(hann, std::max(low, w_coarse - 2 * coarse),
                             std::min(high, w_coarse + 2 * coarse), 0.25 * fine);
  double a = w_fine - 0.25 * fine, b = w_fine + 0.25 * fine;
  const double g = 0.5 * (std::sqrt(5.0) - 1);
  double c = b - g * (b - a), d = a + g * (b - a);
  double fc = HannAmplitude(z, hann, t0, dt, c), fd = HannAmplitude(z, hann, t0, dt, d);
  while (b - a > 1e-12 * std::max(1.0, std::abs(w_fine))) {
    if (fc > fd) {
      b = d, d = c, fd = fc;
      c = b - g * (b - a);
      fc = HannAmplitude(z, hann, t0, dt, c);
    } else {
      a = c, c = d, fc = fd;
      d = a + g * (b - a);
      fd = HannAmplitude(z, hann, t0, dt, d);
    }
  }
  return 0.5 * (a + b);
}

}  // namespace

HarmonicSolution GuessFromQuasiPeriodicSimulation(
    const std::function<void(double, const double*, double*)>& rhs, const Eigen::VectorXd& y0,
    const std::vector<BaseFrequencySearch>& bases, const HarmonicBasis& basis,
    const std::vector<Variable>& variables,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& aux,
    const QuasiPeriodicGuessOptions& options) {
  const int d = basis.num_bases();
  if (static_cast<int>(bases.size()) != d)
    throw std::invalid_argument("GuessFromQuasiPeriodicSimulation: one search per base frequency");
  if (!(options.duration > 0) || !(options.step > 0) || options.sample_every < 1 ||
      !(options.transient >= 0))
    throw std::invalid_argument("GuessFromQuasiPeriodicSimulation: bad window or step");
  for (const auto& b : bases)
    if (!b.known && (!(b.low > 0) || !(b.high > b.low) || b.component < 0 || b.component >= y0.size()))
      throw std::invalid_argument("GuessFromQuasiPeriodicSimulation: bad search band or component");

  // Integrate, keeping samples of the window.
  const int n = static_cast<int>(y0.size());
  Eigen::VectorXd y = y0, k1(n), k2(n), k3(n), k4(n), tmp(n);
  const double h = options.step;
  const long transient_steps = std::lround(options.transient / h);
  const long window_steps = std::lround(options.duration / h);
  double t = 0;
  for (long i = 0; i < transient_steps; ++i, t = i * h) Rk4(rhs, t, h, &y, &k1, &k2, &k3, &k4, &tmp);
  const double t0 = transient_steps * h, dt = h * options.sample_every;
  const long samples = window_steps / options.sample_every + 1;
  Eigen::MatrixXd states(samples, n);
  for (long s = 0; s < samples; ++s) {
    states.row(s) = y.transpose();
    for (int i = 0; i < options.sample_every; ++i) {
      t = t0 + (s * options.sample_every + i) * h;
      Rk4(rhs, t, h, &y, &k1, &k2, &k3, &k4, &tmp);
    }
  }
  if (!states.allFinite())
    throw std::runtime_error("GuessFromQuasiPeriodicSimulation: the simulation blew up");

  std::vector<double> w(d);
  for (int b = 0; b < d; ++b)
    w[b] = bases[b].known ? bases[b].value
                          : PeakFrequency(states.col(bases[b].component), t0, dt, bases[b].low,
                                          bases[b].high);

  // Least-squares fit of every variable on the basis at those frequencies.
  const int C = basis.num_coefficients();
  if (samples < 2 * C) throw std::invalid_argument("GuessFromQuasiPeriodicSimulation: window too short for the basis");
  Eigen::MatrixXd E(samples, C), values(samples, variables.size());
  for (long s = 0; s < samples; ++s) {
    const double ts = t0 + s * dt;
    E(s, 0) = 1;
    for (int k = 1; k < basis.size(); ++k) {
      const double a = basis.Frequency(k, w) * ts;
      E(s, 2 * k - 1) = std::cos(a);
      E(s, 2 * k) = std::sin(a);
    }
    const Eigen::VectorXd v = aux(states.row(s).transpose());
    if (v.size() != static_cast<long>(variables.size()))
      throw std::invalid_argument("GuessFromQuasiPeriodicSimulation: aux gives the wrong size");
    values.row(s) = v.transpose();
  }
  const Eigen::MatrixXd coefficients = E.colPivHouseholderQr().solve(values).transpose();
  return HarmonicSolution(basis, w, coefficients, variables);
}

}  // namespace rmhb::examples
