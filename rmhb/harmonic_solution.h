#ifndef RMHB_HARMONIC_SOLUTION_H_
#define RMHB_HARMONIC_SOLUTION_H_

// A (quasi-)periodic solution: for each variable
//   z(t) = a_0 + sum_k a_k cos(k.w t) + b_k sin(k.w t)
// over the harmonics k of a basis and base frequencies w.

#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rmhb/harmonic_basis.h"
#include "rmhb/polynomial_system.h"

namespace rmhb {

class HarmonicSolution {
 public:
  HarmonicSolution(HarmonicBasis basis, std::vector<double> frequencies,
                   Eigen::MatrixXd coefficients, std::vector<Variable> variables);

  // Projects a function of the torus angles theta (theta_i = w_i t) onto the
  // basis: the way to turn a rough guess (a cos(w t), sin of it, ...) into
  // coefficients for every variable, auxiliaries included.
  static HarmonicSolution FromAngles(
      const HarmonicBasis& basis, std::vector<double> frequencies, std::vector<Variable> variables,
      const std::function<Eigen::VectorXd(const std::vector<double>& theta)>& f);

  const HarmonicBasis& basis() const { return basis_; }
  const std::vector<double>& frequencies() const { return frequencies_; }
  const Eigen::MatrixXd& coefficients() const { return coefficients_; }  // [variable][2K-1]
  const std::vector<Variable>& variables() const { return variables_; }
  int num_variables() const { return static_cast<int>(variables_.size()); }
  int IndexOf(const std::string& name) const;

  double Value(int variable, double t) const;
  double Derivative(int variable, double t) const;
  // max_t |z(t)| estimated on a fine grid over one period (periodic only).
  double Amplitude(int variable) const;
  // Same solution on another basis over the same bases: harmonics not in
  // this one are zero, missing ones are dropped (warm starts across orders).
  HarmonicSolution OnBasis(const HarmonicBasis& basis) const;
  HarmonicSolution WithFrequencies(std::vector<double> frequencies) const;
  // One base: the same orbit on the base g w, for a solution that repeats g
  // times per period (only the multiples of g carry it): harmonic j takes
  // harmonic g j's coefficients, on the periodic basis of order order() / g.
  HarmonicSolution OnMultipleFrequency(int g) const;
  // The same torus with its angles advanced: z(theta + phase). For an
  // autonomous direction this is another solution (the phase is free), which
  // is how a guess is turned to meet a phase condition before the solve.
  HarmonicSolution Shifted(const std::vector<double>& phase) const;

 private:
  HarmonicBasis basis_;
  std::vector<double> frequencies_;
  Eigen::MatrixXd coefficients_;
  std::vector<Variable> variables_;
};

}  // namespace rmhb

#endif  // RMHB_HARMONIC_SOLUTION_H_
