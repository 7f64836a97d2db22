#include "frequency_id/sinusoid_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <Eigen/Cholesky>

namespace rmhb::frequency_id {
namespace {

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr std::size_t kMaxBlockLines = 4;

// A frequency step of a few ulps is rounding jitter, not lack of
// convergence: it counts as no step at all.
double RoundOffAware(double step, double omega) {
  return std::abs(step) <= 4.0 * kEps * std::abs(omega) ? 0.0 : std::abs(step);
}

double WeightedSquaredNorm(const Eigen::VectorXd& weights, const Eigen::MatrixXd& values) {
  return (values.array().square().colwise() * weights.array()).sum();
}

}  // namespace

double SinusoidModel::Amplitude(int k) const {
  return std::sqrt(cos_coefficients.row(k).squaredNorm() + sin_coefficients.row(k).squaredNorm());
}

SinusoidFitter::SinusoidFitter(const SampleGrid& grid, const Eigen::MatrixXd& samples,
                               const Eigen::VectorXd& weights)
    : grid_(grid), samples_(samples) {
  if (samples.rows() != grid.size) {
    throw std::invalid_argument("SinusoidFitter: samples do not match the grid");
  }
  tau_.resize(grid.size);
  for (int n = 0; n < grid.size; ++n) tau_(n) = grid.Tau(n);
  const int channels = static_cast<int>(samples.cols());
  model_.cos_coefficients.resize(0, channels);
  model_.sin_coefficients.resize(0, channels);
  model_.mean = Eigen::RowVectorXd::Zero(channels);
  residual_ = samples_;
  SetWeights(weights);
}

void SinusoidFitter::SetWeights(const Eigen::VectorXd& weights) {
  if (weights.size() != grid_.size) {
    throw std::invalid_argument("SinusoidFitter: weights do not match the grid");
  }
  weights_ = weights;
  weight_sum_ = weights_.sum();
  RefitMean();
}

Eigen::MatrixXd SinusoidFitter::Basis(double omega) const {
  Eigen::MatrixXd basis(grid_.size, 2);
  ForEachPhasor(grid_, omega, [&basis](int n, double c, double s) {
    basis(n, 0) = c;
    basis(n, 1) = s;
  });
  return basis;
}

void SinusoidFitter::RefitMean() {
  const Eigen::RowVectorXd shift = (weights_.transpose() * residual_) / weight_sum_;
  residual_.rowwise() -= shift;
  model_.mean += shift;
}

int SinusoidFitter::AddLine(double omega) {
  const Eigen::MatrixXd basis = Basis(omega);
  const Eigen::MatrixXd weighted = weights_.asDiagonal() * basis;
  const Eigen::Matrix2d gram = basis.transpose() * weighted;
  const Eigen::MatrixXd coefficients = gram.ldlt().solve(weighted.transpose() * residual_);
  residual_.noalias() -= basis * coefficients;
  const int k = num_lines();
  model_.frequencies.push_back(omega);
  model_.cos_coefficients.conservativeResize(k + 1, Eigen::NoChange);
  model_.sin_coefficients.conservativeResize(k + 1, Eigen::NoChange);
  model_.cos_coefficients.row(k) = coefficients.row(0);
  model_.sin_coefficients.row(k) = coefficients.row(1);
  return k;
}

void SinusoidFitter::RemoveLine(int index) {
  const Eigen::MatrixXd basis = Basis(model_.frequencies[index]);
  residual_.noalias() += basis.col(0) * model_.cos_coefficients.row(index);
  residual_.noalias() += basis.col(1) * model_.sin_coefficients.row(index);
  const int k = num_lines();
  model_.frequencies.erase(model_.frequencies.begin() + index);
  for (Eigen::MatrixXd* m : {&model_.cos_coefficients, &model_.sin_coefficients}) {
    Eigen::MatrixXd kept(k - 1, m->cols());
    kept << m->topRows(index), m->bottomRows(k - 1 - index);
    *m = kept;
  }
}

std::vector<std::vector<int>> SinusoidFitter::Clusters(double spacing) const {
  std::vector<int> order(num_lines());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [this](int a, int b) { return model_.frequencies[a] < model_.frequencies[b]; });
  std::vector<std::vector<int>> clusters;
  for (std::size_t i = 0; i < order.size(); ++i) {
    // A chain of close lines (a chirp, a broadened line) is cut into blocks
    // of kMaxBlockLines: a block step costs O(N lines^2), and Gauss-Seidel
    // between neighbouring blocks still converges.
    if (i == 0 || model_.frequencies[order[i]] - model_.frequencies[order[i - 1]] >= spacing ||
        clusters.back().size() >= kMaxBlockLines) {
      clusters.emplace_back();
    }
    clusters.back().push_back(order[i]);
  }
  // Strongest block first: the weaker lines are refined against a residual
  // already cleaned of the large lines' errors.
  auto strength = [this](const std::vector<int>& cluster) {
    double a = 0.0;
    for (int k : cluster) a = std::max(a, model_.Amplitude(k));
    return a;
  };
  std::stable_sort(clusters.begin(), clusters.end(),
                   [&](const std::vector<int>& a, const std::vector<int>& b) {
                     return strength(a) > strength(b);
                   });
  return clusters;
}

double SinusoidFitter::StepLine(int line) {
  const int channels = static_cast<int>(samples_.cols());
  const double omega = model_.frequencies[line];
  const Eigen::VectorXd a = model_.cos_coefficients.row(line).transpose();
  const Eigen::VectorXd b = model_.sin_coefficients.row(line).transpose();

  // Pass 1, at omega: Gram matrix G of (cos, sin), and per channel the
  // cross products of the frequency derivative D = tau (b cos - a sin), the
  // basis and the residual r. Index layout per channel: DD, Dc, Ds, Dr, cr, sr.
  double gcc = 0.0, gcs = 0.0, gss = 0.0, objective = 0.0;
  std::vector<double> sums(6 * channels, 0.0);
  ForEachPhasor(grid_, omega, [&](int n, double c, double s) {
    const double w = weights_(n);
    const double wc = w * c, ws = w * s;
    gcc += wc * c;
    gcs += wc * s;
    gss += ws * s;
    for (int ch = 0; ch < channels; ++ch) {
      const double r = residual_(n, ch);
      const double d = tau_(n) * (b(ch) * c - a(ch) * s);
      const double wd = w * d;
      double* acc = &sums[6 * ch];
      acc[0] += wd * d;
      acc[1] += wd * c;
      acc[2] += wd * s;
      acc[3] += wd * r;
      acc[4] += wc * r;
      acc[5] += ws * r;
      objective += w * r * r;
    }
  });
  const double det = gcc * gss - gcs * gcs;
  if (!(det > 0.0)) return 0.0;
  // h' G^-1 k for 2-vectors h, k.
  auto g_inverse = [&](double h0, double h1, double k0, double k1) {
    return (h0 * (gss * k0 - gcs * k1) + h1 * (gcc * k1 - gcs * k0)) / det;
  };
  double reduced = 0.0, rhs = 0.0;
  for (int ch = 0; ch < channels; ++ch) {
    const double* acc = &sums[6 * ch];
    reduced += acc[0] - g_inverse(acc[1], acc[2], acc[1], acc[2]);
    rhs += acc[3] - g_inverse(acc[1], acc[2], acc[4], acc[5]);
  }
  if (!(reduced > 0.0)) return 0.0;
  const double max_step = 0.25 * grid_.BinWidth();
  double step = std::clamp(rhs / reduced, -max_step, max_step);
  if (!std::isfinite(step)) return 0.0;

  // Pass 2, for a trial omega + step: the optimal coefficients there and the
  // objective they leave, from sums over r_S = r + a cos + b sin (the
  // residual with this line taken out). Halve the step until the objective
  // does not grow beyond what rounding of the sums can explain.
  Eigen::VectorXd new_a(channels), new_b(channels);
  bool accepted = false;
  for (int attempt = 0; attempt < 6 && !accepted; ++attempt, step *= 0.5) {
    double hcc = 0.0, hcs = 0.0, hss = 0.0, block_energy = 0.0;
    std::vector<double> cross(2 * channels, 0.0);
    ForEachPhasorPair(grid_, omega, omega + step,
                      [&](int n, double c_old, double s_old, double c, double s) {
                        const double w = weights_(n);
                        hcc += w * c * c;
                        hcs += w * c * s;
                        hss += w * s * s;
                        for (int ch = 0; ch < channels; ++ch) {
                          const double r_s = residual_(n, ch) + a(ch) * c_old + b(ch) * s_old;
                          const double wr = w * r_s;
                          cross[2 * ch] += wr * c;
                          cross[2 * ch + 1] += wr * s;
                          block_energy += wr * r_s;
                        }
                      });
    const double new_det = hcc * hss - hcs * hcs;
    if (!(new_det > 0.0)) continue;
    double new_objective = block_energy;
    for (int ch = 0; ch < channels; ++ch) {
      const double k0 = cross[2 * ch], k1 = cross[2 * ch + 1];
      new_a(ch) = (hss * k0 - hcs * k1) / new_det;
      new_b(ch) = (hcc * k1 - hcs * k0) / new_det;
      new_objective -= new_a(ch) * k0 + new_b(ch) * k1;
    }
    // new_objective is a difference of O(block_energy) sums.
    const double noise = 64.0 * kEps * block_energy;
    accepted = new_a.allFinite() && new_b.allFinite() && new_objective <= objective + noise;
    if (accepted) break;
  }
  if (!accepted) return 0.0;

  // Pass 3: swap the old line for the new one in the residual.
  const double new_omega = omega + step;
  ForEachPhasorPair(grid_, omega, new_omega,
                    [&](int n, double c_old, double s_old, double c, double s) {
                      for (int ch = 0; ch < channels; ++ch) {
                        residual_(n, ch) += (a(ch) * c_old + b(ch) * s_old) -
                                            (new_a(ch) * c + new_b(ch) * s);
                      }
                    });
  model_.frequencies[line] = new_omega;
  model_.cos_coefficients.row(line) = new_a.transpose();
  model_.sin_coefficients.row(line) = new_b.transpose();
  return RoundOffAware(step, omega) * model_.Amplitude(line);
}

double SinusoidFitter::StepBlock(const std::vector<int>& lines) {
  if (lines.size() == 1) return StepLine(lines[0]);
  const int s = static_cast<int>(lines.size());
  const int channels = static_cast<int>(samples_.cols());
  const int size = grid_.size;

  Eigen::MatrixXd basis(size, 2 * s);
  Eigen::MatrixXd theta(2 * s, channels);
  for (int j = 0; j < s; ++j) {
    const int k = lines[j];
    basis.middleCols(2 * j, 2) = Basis(model_.frequencies[k]);
    theta.row(2 * j) = model_.cos_coefficients.row(k);
    theta.row(2 * j + 1) = model_.sin_coefficients.row(k);
  }
  const Eigen::MatrixXd weighted_basis = weights_.asDiagonal() * basis;
  const Eigen::MatrixXd gram = basis.transpose() * weighted_basis;
  const Eigen::LDLT<Eigen::MatrixXd> gram_ldlt(gram);

  // Gauss-Newton for the frequencies with the coefficients eliminated
  // (Schur complement of the coefficient blocks, which share the Gram
  // matrix across channels): the cost stays linear in the channel count.
  Eigen::MatrixXd reduced = Eigen::MatrixXd::Zero(s, s);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(s);
  Eigen::MatrixXd derivative(size, s);
  for (int c = 0; c < channels; ++c) {
    for (int j = 0; j < s; ++j) {
      // d/domega (a cos + b sin)(omega tau) = tau (b cos - a sin)
      derivative.col(j) = tau_.cwiseProduct(theta(2 * j + 1, c) * basis.col(2 * j) -
                                            theta(2 * j, c) * basis.col(2 * j + 1));
    }
    const Eigen::MatrixXd weighted_derivative = weights_.asDiagonal() * derivative;
    const Eigen::MatrixXd cross = weighted_derivative.transpose() * basis;  // s x 2s
    const Eigen::VectorXd g_theta = weighted_basis.transpose() * residual_.col(c);
    reduced.noalias() += derivative.transpose() * weighted_derivative;
    reduced.noalias() -= cross * gram_ldlt.solve(cross.transpose());
    rhs.noalias() += weighted_derivative.transpose() * residual_.col(c);
    rhs.noalias() -= cross * gram_ldlt.solve(g_theta);
  }
  // A line with (numerically) no amplitude has no frequency to refine.
  const double diagonal_scale = reduced.diagonal().cwiseAbs().maxCoeff();
  for (int j = 0; j < s; ++j) {
    if (!(reduced(j, j) > 1e-12 * diagonal_scale)) {
      reduced.row(j).setZero();
      reduced.col(j).setZero();
      reduced(j, j) = 1.0;
      rhs(j) = 0.0;
    }
  }
  Eigen::VectorXd step = reduced.ldlt().solve(rhs);
  if (!step.allFinite()) return 0.0;
  // Never jump by more than a quarter bin: further than that the linear
  // model is meaningless and the line could hop onto a neighbour.
  const double max_step = 0.25 * grid_.BinWidth();
  const double largest = step.cwiseAbs().maxCoeff();
  if (largest > max_step) step *= max_step / largest;

  Eigen::MatrixXd block_residual = residual_;
  block_residual.noalias() += basis * theta;
  const double objective = WeightedSquaredNorm(weights_, residual_);
  const double block_energy = WeightedSquaredNorm(weights_, block_residual);
  // Objective changes below this are rounding noise of r_S - basis * theta.
  const double noise = 64.0 * kEps * std::sqrt(objective * block_energy) +
                       (64.0 * kEps) * (64.0 * kEps) * block_energy;

  for (int attempt = 0; attempt < 6; ++attempt) {
    Eigen::MatrixXd new_basis(size, 2 * s);
    for (int j = 0; j < s; ++j) {
      new_basis.middleCols(2 * j, 2) = Basis(model_.frequencies[lines[j]] + step(j));
    }
    const Eigen::MatrixXd new_weighted = weights_.asDiagonal() * new_basis;
    const Eigen::LDLT<Eigen::MatrixXd> new_gram(new_basis.transpose() * new_weighted);
    const Eigen::MatrixXd new_theta = new_gram.solve(new_weighted.transpose() * block_residual);
    Eigen::MatrixXd new_residual = block_residual;
    new_residual.noalias() -= new_basis * new_theta;
    const double new_objective = WeightedSquaredNorm(weights_, new_residual);
    if (new_theta.allFinite() && new_objective <= objective + noise) {
      double change = 0.0;
      for (int j = 0; j < s; ++j) {
        const int k = lines[j];
        model_.frequencies[k] += step(j);
        model_.cos_coefficients.row(k) = new_theta.row(2 * j);
        model_.sin_coefficients.row(k) = new_theta.row(2 * j + 1);
        change = std::max(change, RoundOffAware(step(j), model_.frequencies[k]) *
                                      model_.Amplitude(k));
      }
      residual_ = std::move(new_residual);
      return change;
    }
    step *= 0.5;
  }
  return 0.0;
}

PolishSummary SinusoidFitter::Polish(const PolishOptions& options) {
  PolishSummary summary;
  if (num_lines() == 0) {
    summary.converged = true;
    return summary;
  }
  for (int sweep = 0; sweep < options.max_sweeps; ++sweep) {
    const std::vector<std::vector<int>> clusters = Clusters(options.cluster_spacing);
    summary.num_clusters = static_cast<int>(clusters.size());
    summary.largest_cluster = 0;
    double change = 0.0;
    for (const std::vector<int>& cluster : clusters) {
      summary.largest_cluster = std::max(summary.largest_cluster, static_cast<int>(cluster.size()));
      change = std::max(change, StepBlock(cluster));
    }
    RefitMean();
    double strongest = 0.0;
    for (int k = 0; k < num_lines(); ++k) strongest = std::max(strongest, model_.Amplitude(k));
    summary.sweeps = sweep + 1;
    summary.last_change = strongest > 0.0 ? change * grid_.Duration() / strongest : 0.0;
    if (summary.last_change <= options.tolerance) {
      summary.converged = true;
      break;
    }
  }
  return summary;
}

bool SinusoidFitter::FitAllCoefficients() {
  const int lines = num_lines();
  const int columns = 1 + 2 * lines;
  const int channels = static_cast<int>(samples_.cols());
  // The design matrix [1, cos_1, sin_1, ...] is built a chunk of rows at a
  // time: whole, it would be samples x (2 lines + 1) doubles.
  constexpr int kChunk = 64 * kPhasorAnchorStride;
  Eigen::MatrixXd design(kChunk, columns);
  auto fill_design = [&](int begin, int end) {
    design.col(0).setOnes();
    for (int k = 0; k < lines; ++k) {
      ForEachPhasorInRange(grid_, model_.frequencies[k], begin, end,
                           [&](int n, double c, double s) {
                             design(n - begin, 1 + 2 * k) = c;
                             design(n - begin, 2 + 2 * k) = s;
                           });
    }
  };
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(columns, columns);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(columns, channels);
  for (int begin = 0; begin < grid_.size; begin += kChunk) {
    const int rows = std::min(kChunk, grid_.size - begin);
    fill_design(begin, begin + rows);
    const auto block = design.topRows(rows);
    const Eigen::MatrixXd weighted = weights_.segment(begin, rows).asDiagonal() * block;
    normal.noalias() += weighted.transpose() * block;
    rhs.noalias() += weighted.transpose() * samples_.middleRows(begin, rows);
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
  if (ldlt.info() != Eigen::Success) return false;
  Eigen::MatrixXd coefficients = ldlt.solve(rhs);
  // One step of iterative refinement recovers what forming the normal
  // equations lost; the last pass leaves the residual behind.
  Eigen::MatrixXd residual(grid_.size, channels);
  for (int pass = 0; pass < 2; ++pass) {
    rhs.setZero();
    for (int begin = 0; begin < grid_.size; begin += kChunk) {
      const int rows = std::min(kChunk, grid_.size - begin);
      fill_design(begin, begin + rows);
      const auto block = design.topRows(rows);
      residual.middleRows(begin, rows) = samples_.middleRows(begin, rows);
      residual.middleRows(begin, rows).noalias() -= block * coefficients;
      if (pass == 0) {
        rhs.noalias() += (weights_.segment(begin, rows).asDiagonal() * block).transpose() *
                         residual.middleRows(begin, rows);
      }
    }
    if (pass == 0) coefficients += ldlt.solve(rhs);
  }
  if (!coefficients.allFinite()) return false;
  model_.mean = coefficients.row(0);
  for (int k = 0; k < lines; ++k) {
    model_.cos_coefficients.row(k) = coefficients.row(1 + 2 * k);
    model_.sin_coefficients.row(k) = coefficients.row(2 + 2 * k);
  }
  residual_ = std::move(residual);
  return true;
}

std::vector<double> SinusoidFitter::FrequencyStandardErrors(double cluster_spacing) const {
  const int channels = static_cast<int>(samples_.cols());
  const Eigen::RowVectorXd rms = WeightedResidualRms();
  const Eigen::VectorXd squared_weights = weights_.cwiseAbs2();
  std::vector<double> errors(num_lines(), 0.0);
  for (const std::vector<int>& lines : Clusters(cluster_spacing)) {
    const int s = static_cast<int>(lines.size());
    const int params = s + 2 * s * channels;
    // Full Jacobian of the block, one channel at a time: J_c = [D_c | 0 .. basis .. 0].
    Eigen::MatrixXd basis(grid_.size, 2 * s);
    for (int j = 0; j < s; ++j) basis.middleCols(2 * j, 2) = Basis(model_.frequencies[lines[j]]);
    Eigen::MatrixXd hessian = Eigen::MatrixXd::Zero(params, params);
    Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(params, params);
    Eigen::MatrixXd jacobian(grid_.size, 3 * s);
    for (int c = 0; c < channels; ++c) {
      for (int j = 0; j < s; ++j) {
        const int k = lines[j];
        jacobian.col(j) = tau_.cwiseProduct(model_.sin_coefficients(k, c) * basis.col(2 * j) -
                                            model_.cos_coefficients(k, c) * basis.col(2 * j + 1));
      }
      jacobian.rightCols(2 * s) = basis;
      const Eigen::MatrixXd h = jacobian.transpose() * weights_.asDiagonal() * jacobian;
      const Eigen::MatrixXd m =
          rms(c) * rms(c) * (jacobian.transpose() * squared_weights.asDiagonal() * jacobian);
      // Scatter into [omega (s) | theta_0 (2s) | theta_1 (2s) | ...].
      const int offset = s + 2 * s * c;
      for (Eigen::MatrixXd* target : {&hessian, &meat}) {
        const Eigen::MatrixXd& source = (target == &hessian) ? h : m;
        target->topLeftCorner(s, s) += source.topLeftCorner(s, s);
        target->block(0, offset, s, 2 * s) += source.topRightCorner(s, 2 * s);
        target->block(offset, 0, 2 * s, s) += source.bottomLeftCorner(2 * s, s);
        target->block(offset, offset, 2 * s, 2 * s) += source.bottomRightCorner(2 * s, 2 * s);
      }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(hessian);
    const Eigen::MatrixXd covariance = ldlt.solve(ldlt.solve(meat).transpose());
    for (int j = 0; j < s; ++j) {
      const double variance = covariance(j, j);
      errors[lines[j]] = (std::isfinite(variance) && variance > 0.0)
                             ? std::sqrt(variance)
                             : std::numeric_limits<double>::infinity();
    }
  }
  return errors;
}

Eigen::RowVectorXd SinusoidFitter::WeightedResidualRms() const {
  return ((weights_.transpose() * residual_.cwiseAbs2()) / weight_sum_).cwiseSqrt();
}

}  // namespace rmhb::frequency_id
