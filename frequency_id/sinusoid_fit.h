#ifndef RMHB_FREQUENCY_ID_SINUSOID_FIT_H_
#define RMHB_FREQUENCY_ID_SINUSOID_FIT_H_

#include <vector>

#include <Eigen/Core>

#include "frequency_id/sample_grid.h"

namespace rmhb::frequency_id {

// A sum of sinusoids shared by all channels, phases measured from the record
// centre (tau = t - grid.Center()):
//
//   x_c(t) = mean_c + sum_k cos_coefficients(k, c) cos(omega_k tau)
//                   + sin_coefficients(k, c) sin(omega_k tau).
struct SinusoidModel {
  std::vector<double> frequencies;
  Eigen::MatrixXd cos_coefficients;  // lines x channels
  Eigen::MatrixXd sin_coefficients;  // lines x channels
  Eigen::RowVectorXd mean;           // 1 x channels

  int num_lines() const { return static_cast<int>(frequencies.size()); }
  // Euclidean norm over channels of the amplitudes of line k.
  double Amplitude(int k) const;
};

struct PolishOptions {
  int max_sweeps = 30;
  // A sweep has converged when every line k moved by
  //   |d omega_k| * T * A_k <= tolerance * A_max,
  // i.e. when no line changes the model by more than tolerance relative to
  // the strongest line: weak lines, whose frequencies are only as good as
  // their share of the signal, are not asked for more than that.
  double tolerance = 1e-12;
  // Lines closer than this (rad per unit time) are refined jointly as one
  // block: their windowed responses overlap too much for one-at-a-time
  // updates to converge quickly.
  double cluster_spacing = 0.0;
};

struct PolishSummary {
  int sweeps = 0;
  bool converged = false;
  double last_change = 0.0;  // the convergence measure of the last sweep
  int num_clusters = 0;
  int largest_cluster = 0;
};

// Weighted least squares for the sinusoidal model,
//
//   minimise  sum_c sum_n w_n (x_nc - model_c(t_n))^2,
//
// over all frequencies and coefficients. With a smooth window as the weight,
// lines not (yet) in the model leak into the fit only through the window's
// fast-decaying sidelobes, and when the record is an exact sum of the modelled
// lines the minimum is the exact answer: the frequencies come out at
// round-off level, not at the T^-(2q+2) bias of a one-line-at-a-time NAFF.
//
// The fitter keeps the current residual so that adding, refining and
// removing lines costs O(samples) each.
class SinusoidFitter {
 public:
  SinusoidFitter(const SampleGrid& grid, const Eigen::MatrixXd& samples,
                 const Eigen::VectorXd& weights);

  const SampleGrid& grid() const { return grid_; }
  const SinusoidModel& model() const { return model_; }
  const Eigen::MatrixXd& residual() const { return residual_; }
  const Eigen::VectorXd& weights() const { return weights_; }
  int num_lines() const { return model_.num_lines(); }

  // Switches to other weights (another window); the model is kept.
  void SetWeights(const Eigen::VectorXd& weights);

  // Adds a line at `omega`, its coefficients fitted to the current residual
  // (which it is then removed from). Returns its index.
  int AddLine(double omega);
  void RemoveLine(int index);

  // Block Gauss-Seidel over the lines, strongest block first: each block
  // (a line, or a cluster of close lines) gets a Gauss-Newton step on its
  // frequencies with the other lines held fixed, then its coefficients are
  // refitted exactly at the new frequencies. The weighted mean is refitted
  // every sweep.
  PolishSummary Polish(const PolishOptions& options);

  // Joint weighted least squares of the mean and all coefficients at the
  // current frequencies (normal equations plus two steps of iterative
  // refinement, enough for the mild conditioning of windowed sinusoids).
  // Returns false if the system is singular (coincident lines).
  bool FitAllCoefficients();

  // Standard error of each frequency: the sandwich covariance
  // H^-1 (J' W^2 J sigma^2) H^-1 of the weighted fit of its block, with the
  // per-channel noise level sigma^2 estimated from the weighted residual.
  std::vector<double> FrequencyStandardErrors(double cluster_spacing) const;

  // Weighted RMS of the residual per channel: sqrt(sum w r^2 / sum w).
  Eigen::RowVectorXd WeightedResidualRms() const;

 private:
  // cos / sin of omega * tau for one line, as the two columns of an N x 2 matrix.
  Eigen::MatrixXd Basis(double omega) const;
  std::vector<std::vector<int>> Clusters(double spacing) const;
  // One damped Gauss-Newton step on the frequencies of `lines`; returns the
  // largest |d omega| * A_k of the block.
  double StepBlock(const std::vector<int>& lines);
  // The same for a lone line, in three streaming passes over the samples
  // without N-sized temporaries: the common case, and the hot loop.
  double StepLine(int line);
  void RefitMean();

  SampleGrid grid_;
  Eigen::MatrixXd samples_;
  Eigen::VectorXd weights_;
  double weight_sum_ = 0.0;
  Eigen::VectorXd tau_;
  SinusoidModel model_;
  Eigen::MatrixXd residual_;
};

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_SINUSOID_FIT_H_
