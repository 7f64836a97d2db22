#ifndef RMHB_EXAMPLES_QUASI_PERIODIC_GUESS_H_
#define RMHB_EXAMPLES_QUASI_PERIODIC_GUESS_H_

// A starting guess for a quasi-periodic response, from a simulation of the
// original equations: integrate (fixed-step RK4) past any transient, measure
// the unknown base frequencies as the strongest spectral peaks of chosen state
// components, then fit the analysed window by least squares on a small basis.
//
// Why a simulation: on a torus with a slow beat (the asymmetric pendulum's
// 1:1 internal resonance) the amplitudes and the slow frequency depend on the
// energy exchange, which no linear or single-harmonic guess gets right, and
// Newton on a thousand unknowns does not recover from a wrong beat. A
// windowed spectral peak gives the frequencies to ~1e-7, the fit the main
// coefficients to ~1e-4; Newton then converges in a few chord steps.
//
// The window must hold several beat periods, or neighbouring peaks of the
// beat (spaced by the slow frequency) merge: duration >> 2 pi / slow.

#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_solution.h"

namespace rmhb::examples {

struct BaseFrequencySearch {
  bool known = false;
  double value = 0;  // the known frequency
  // Unknown: the strongest peak of state component `component` in [low, high].
  int component = 0;
  double low = 0, high = 0;
};

struct QuasiPeriodicGuessOptions {
  double transient = 0;   // integrated and discarded (to reach an attracting torus)
  double duration = 0;    // analysed window, after the transient
  double step = 0.05;     // RK4 step
  int sample_every = 5;   // samples taken every this many steps
};

// `rhs` is the original ODE, `y0` its state at t = 0; `aux` maps a state to
// every harmonic balance variable. The fit uses absolute time t, so the
// result is the torus function at t = 0 (forcing phases stay right). Throws
// std::invalid_argument on misuse (sizes, empty window, bad search band).
HarmonicSolution GuessFromQuasiPeriodicSimulation(
    const std::function<void(double, const double*, double*)>& rhs, const Eigen::VectorXd& y0,
    const std::vector<BaseFrequencySearch>& bases, const HarmonicBasis& basis,
    const std::vector<Variable>& variables,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd& y)>& aux,
    const QuasiPeriodicGuessOptions& options);

}  // namespace rmhb::examples

#endif  // RMHB_EXAMPLES_QUASI_PERIODIC_GUESS_H_
