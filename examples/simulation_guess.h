#ifndef RMHB_EXAMPLES_SIMULATION_GUESS_H_
#define RMHB_EXAMPLES_SIMULATION_GUESS_H_

// A starting guess for a self-excited oscillator whose shape is far from a
// sinusoid (Van der Pol relaxation): integrate past the transient with a
// fixed-step RK4, measure the period between two maxima of y[0], and project
// one period onto the basis. Only a guess: accuracy comes from the solver.

#include <functional>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_solution.h"

namespace rmhb::examples {

// `aux` maps the integrated state to all harmonic balance variables.
HarmonicSolution GuessFromSimulation(
    const std::function<void(double, const double*, double*)>& rhs, Eigen::VectorXd y0,
    double period_guess, int transient_periods, const HarmonicBasis& basis,
    const std::vector<Variable>& variables,
    const std::function<Eigen::VectorXd(const Eigen::VectorXd& y)>& aux);

}  // namespace rmhb::examples

#endif  // RMHB_EXAMPLES_SIMULATION_GUESS_H_
