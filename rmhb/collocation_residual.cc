#include "rmhb/collocation_residual.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace rmhb {
namespace {

// Up to this many unknowns an evaluation is cheaper through the sampled maps
// (J in O(rows M n)) than through the Toeplitz-plus-Hankel blocks (METHOD.md
// s.21): F + J of the forced Duffing 1.4x faster at 7 unknowns, even at 11,
// 1.4x slower at 17; the Rayleigh-Plesset recast 1.1x faster at 14.
constexpr int kSampledMapUnknowns = 14;

}  // namespace

CollocationResidual::CollocationResidual(const HarmonicBalanceProblem& problem,
                                         const HarmonicBasis& basis, const Sampling& sampling,
                                         bool condense_definitions)
    : problem_(problem), basis_(basis) {
  problem.Validate();
  if (basis.num_bases() != static_cast<int>(problem.frequencies.size()))
    throw std::invalid_argument("the basis has " + std::to_string(basis.num_bases()) +
                                " bases but the problem " +
                                std::to_string(problem.frequencies.size()) + " frequencies");
  transform_ = std::make_unique<SpectralTransform>(basis, sampling);
  n_ = problem.system.num_variables();
  degree_ = std::max(1, problem.system.Degree());
  C_ = basis.num_coefficients();
  M_ = transform_->num_samples();

  unknown_index_.assign(basis.num_bases(), -1);
  int nu = 0;
  for (int b = 0; b < basis.num_bases(); ++b)
    if (!problem.unknown_frequency.empty() && problem.unknown_frequency[b]) unknown_index_[b] = nu++;
  num_unknowns_ = n_ * C_ + nu;

  // Compile: slots and time functions get dense indices; terms keep lists.
  std::map<Slot, int> slot_index;
  std::map<TimeFunction, int> time_index;
  int row = 0;
  for (const auto& eq : problem.system.equations()) {
    CompiledEquation ce;
    ce.first_row = row;
    ce.balance_constant = eq.balance_constant;
    row += eq.balance_constant ? C_ : C_ - 1;
    if (eq.pointwise) {
      ce.pointwise = eq.pointwise.get();
      ce.pointwise_index = static_cast<int>(pointwise_values_.size());
      pointwise_values_.emplace_back(M_, 1 + eq.pointwise->slots.size());
      for (const Slot& slot : eq.pointwise->slots) {
        auto [it, fresh] = slot_index.try_emplace(slot, static_cast<int>(slots_.size()));
        if (fresh) slots_.push_back({slot.variable, slot.derivative});
        ce.slots.push_back(it->second);
      }
    }
    for (const auto& [mono, c] : eq.lhs.terms()) {
      CompiledTerm t{c, -1, {}};
      if (mono.time.kind != TimeFunction::Kind::kOne) {
        auto [it, fresh] = time_index.try_emplace(mono.time, static_cast<int>(time_samples_.size()));
        if (fresh) {
          Eigen::VectorXd v(M_);
          transform_->Phases(mono.time.harmonic, v.data());
          for (long s = 0; s < M_; ++s)
            v(s) = mono.time.kind == TimeFunction::Kind::kCos ? std::cos(v(s)) : std::sin(v(s));
          time_samples_.push_back(std::move(v));
        }
        t.time = it->second;
      }
      for (const auto& [slot, power] : mono.factors) {
        auto [it, fresh] = slot_index.try_emplace(slot, static_cast<int>(slots_.size()));
        if (fresh) slots_.push_back({slot.variable, slot.derivative});
        t.factors.push_back({it->second, power});
        bool listed = false;
        for (int s : ce.slots) listed |= s == it->second;
        if (!listed) ce.slots.push_back(it->second);
      }
      ce.terms.push_back(std::move(t));
    }
    equations_.push_back(std::move(ce));
  }
  num_residuals_ = row + static_cast<int>(problem.conditions.size());

  layout_size_ = num_unknowns_;
  frequency_column_ = n_ * C_;
  definitions_.assign(n_, Definition{});
  for (int j = 0; j < n_; ++j) column_.push_back(j * C_);
  if (condense_definitions) SetUpCondensation();
  full_unknowns_ = num_unknowns_;
  full_residuals_ = num_residuals_;
  SetUpSymmetries();

  slot_samples_.assign(slots_.size(), Eigen::VectorXd(M_));
  work_.resize(M_);
  term_.resize(M_);
  proj_.resize(C_);
  coef_.resize(C_);
  rates_.resize(basis.size());
  const std::vector<int> first_harmonic{1};
  sample_phase_.resize(M_);
  transform_->Phases(first_harmonic, sample_phase_.data());
  SetUpLinearAlgebra();
  // pow(largest sample, degree) is finite exactly below this bound.
  overflow_bound_ = std::pow(std::numeric_limits<double>::max(), 1.0 / degree_);
  sampled_maps_eligible_ = basis.num_bases() == 1 && nu == 0 && problem.conditions.empty() &&
                           pointwise_values_.empty() && num_unknowns_ <= kSampledMapUnknowns;
}

void CollocationResidual::SetUpLinearAlgebra() {
  auto inverse = [](const std::vector<int>& kept, int size) {
    std::vector<int> reduced(size, -1);
    if (kept.empty())
      for (int i = 0; i < size; ++i) reduced[i] = i;
    for (size_t i = 0; i < kept.size(); ++i) reduced[kept[i]] = static_cast<int>(i);
    return reduced;
  };
  reduced_row_ = inverse(kept_residuals_, full_residuals_);
  reduced_column_ = inverse(kept_unknowns_, full_unknowns_);
  row_targets_.assign(equations_.size(), std::vector<int>(C_, -1));
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    const int skip = eq.balance_constant ? 0 : 1;
    for (int c = skip; c < C_; ++c) row_targets_[i][c] = reduced_row_[eq.first_row + c - skip];
  }
  column_target_.resize(C_);
  if (!kept_unknowns_.empty()) SetUpKeptHarmonics();
  tangent_samples_.assign(slots_.size(), Eigen::VectorXd(M_));
  // Which (equation, unknown variable) blocks are nonzero: a condensed
  // variable's slots land on its source's columns.
  std::vector<std::pair<int, int>> blocks;
  int equations = 0, variables = 0;
  for (const CompiledEquation& eq : equations_) {
    if (eq.first_row < 0) continue;
    for (int slot : eq.slots) {
      const int j = slots_[slot].variable;
      blocks.emplace_back(equations, definitions_[j].source >= 0 ? definitions_[j].source : j);
    }
    ++equations;
  }
  for (int j = 0; j < n_; ++j) variables += column_[j] >= 0;
  std::sort(blocks.begin(), blocks.end());
  blocks.erase(std::unique(blocks.begin(), blocks.end()), blocks.end());
  if (equations > 0 && variables > 0) density_ = double(blocks.size()) / (double(equations) * variables);
}

void CollocationResidual::SetUpSymmetries() {
  if (problem_.symmetries.empty()) return;
  const int d = basis_.num_bases();
  kept_unknowns_.reserve(full_unknowns_);
  kept_residuals_.reserve(full_residuals_);
  for (int j = 0; j < n_; ++j)
    for (int c = 0; c < C_; ++c) {
      bool keep = true;
      for (const auto& s : problem_.symmetries) keep = keep && s.AllowsCoefficient(basis_, c, s.sign[j]);
      // In the condensed layout (column_ is j C_ without condensation).
      if (keep && column_[j] >= 0) kept_unknowns_.push_back(column_[j] + c);
    }
  for (int u = frequency_column_; u < full_unknowns_; ++u) kept_unknowns_.push_back(u);
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;  // condensed away
    const int skip = eq.balance_constant ? 0 : 1;
    std::vector<int> signs;
    for (const auto& s : problem_.symmetries)
      signs.push_back(s.EquationSign(problem_.system, static_cast<int>(i), d));
    for (int c = skip; c < C_; ++c) {
      bool keep = true;
      for (size_t k = 0; k < signs.size(); ++k)
        keep = keep && problem_.symmetries[k].AllowsCoefficient(basis_, c, signs[k]);
      if (keep) kept_residuals_.push_back(eq.first_row + c - skip);
    }
  }
  // A condition a time reversal meets identically (x'(0) = 0 for an even x)
  // has a zero row on the subspace: dropped.
  const int first_condition = full_residuals_ - static_cast<int>(problem_.conditions.size());
  for (size_t c = 0; c < problem_.conditions.size(); ++c) {
    bool holds = false;
    for (const auto& s : problem_.symmetries)
      holds = holds || ClassifyCondition(s, problem_.conditions[c]) == ConditionOnSubspace::kHolds;
    if (!holds) kept_residuals_.push_back(first_condition + static_cast<int>(c));
  }
  num_unknowns_ = static_cast<int>(kept_unknowns_.size());
  num_residuals_ = static_cast<int>(kept_residuals_.size());
  full_x_.setZero(full_unknowns_);
}

void CollocationResidual::SetUpKeptHarmonics() {
  // Harmonic k of equation i's rows, or of variable j's columns (through its
  // definition when condensed), is kept when one of its coefficients is.
  row_harmonics_.assign(equations_.size(), std::vector<char>(basis_.size(), 0));
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    const int skip = eq.balance_constant ? 0 : 1;
    for (int c = skip; c < C_; ++c)
      if (reduced_row_[eq.first_row + c - skip] >= 0) row_harmonics_[i][(c + 1) / 2] = 1;
  }
  const std::vector<double> unit_rates(basis_.size(), 1.0);
  column_harmonics_.assign(n_, std::vector<char>(basis_.size(), 0));
  for (int j = 0; j < n_; ++j)
    for (int c = 0; c < C_; ++c) {
      int column = 0;
      double factor = 0;
      if (ChainColumn(j, c, unit_rates, &column, &factor) && reduced_column_[column] >= 0)
        column_harmonics_[j][(c + 1) / 2] = 1;
    }
  auto coefficients = [&](const std::vector<char>& harmonics) {
    std::vector<int> kept;
    kept.reserve(C_);
    for (int c = 0; c < C_; ++c)
      if (harmonics[(c + 1) / 2]) kept.push_back(c);
    return kept;
  };
  for (const auto& h : row_harmonics_) row_coefficients_.push_back(coefficients(h));
  for (const auto& h : column_harmonics_) column_coefficients_.push_back(coefficients(h));
}

void CollocationResidual::SetUpCondensation() {
  std::vector<bool> is_source(n_, false);
  for (size_t i = 0; i < equations_.size(); ++i) {
    const Equation& eq = problem_.system.equations()[i];
    if (!eq.balance_constant || eq.lhs.terms().size() != 2) continue;
    int a = -1, b = -1;
    double ca = 0, cb = 0;
    bool linear = true;
    for (const auto& [mono, c] : eq.lhs.terms()) {
      if (mono.time.kind != TimeFunction::Kind::kOne || mono.factors.size() != 1 ||
          mono.factors[0].second != 1) {
        linear = false;
        break;
      }
      const Slot& slot = mono.factors[0].first;
      if (slot.derivative == 1) a = slot.variable, ca = c;
      else b = slot.variable, cb = c;
    }
    if (!linear || a < 0 || b < 0 || a == b || cb == 0) continue;
    // No chains: a source stays an unknown, a defined variable defines nothing.
    if (definitions_[a].source >= 0 || definitions_[b].source >= 0 || is_source[b]) continue;
    definitions_[b] = {a, -ca / cb};
    is_source[a] = true;
    equations_[i].first_row = -1;
    ++num_condensed_;
  }
  if (num_condensed_ == 0) return;
  int row = 0;
  for (CompiledEquation& eq : equations_) {
    if (eq.first_row < 0) continue;
    eq.first_row = row;
    row += eq.balance_constant ? C_ : C_ - 1;
  }
  num_residuals_ = row + static_cast<int>(problem_.conditions.size());
  int column = 0;
  for (int j = 0; j < n_; ++j) {
    column_[j] = definitions_[j].source >= 0 ? -1 : column;
    if (column_[j] >= 0) column += C_;
  }
  frequency_column_ = column;
  num_unknowns_ = column + (layout_size_ - n_ * C_);
  expanded_.resize(layout_size_);
}

void CollocationResidual::Expand(const Eigen::VectorXd& x, Eigen::VectorXd* full) const {
  full->resize(layout_size_);
  for (int j = 0; j < n_; ++j)
    if (column_[j] >= 0) full->segment(j * C_, C_) = x.segment(column_[j], C_);
  const int nu = layout_size_ - n_ * C_;
  full->tail(nu) = x.tail(nu);
  std::vector<double> w;
  Frequencies(*full, &w);
  for (int j = 0; j < n_; ++j) {
    const Definition& d = definitions_[j];
    if (d.source < 0) continue;
    const double* A = full->data() + d.source * C_;
    double* B = full->data() + j * C_;
    B[0] = 0;
    for (int k = 1; k < basis_.size(); ++k) {
      const double rate = d.ratio * basis_.Frequency(k, w);
      B[2 * k - 1] = rate * A[2 * k];
      B[2 * k] = -rate * A[2 * k - 1];
    }
  }
}

bool CollocationResidual::ChainColumn(int j, int c, const std::vector<double>& rates, int* column,
                                      double* factor) const {
  if (column_[j] >= 0) {
    *column = column_[j] + c;
    *factor = 1;
    return true;
  }
  // dB/dA = ratio D(w): cos_k <- rate sin_k, sin_k <- -rate cos_k.
  if (c == 0) return false;
  const Definition& d = definitions_[j];
  const int k = (c + 1) / 2;
  const double rate = d.ratio * rates[k];
  *column = column_[d.source] + (c % 2 ? c + 1 : c - 1);
  *factor = c % 2 ? rate : -rate;
  return true;
}

void CollocationResidual::AddToColumn(Eigen::MatrixXd* J, int column, int row, int count, double factor,
                                      const double* values) const {
  if (kept_unknowns_.empty()) {
    J->col(column).segment(row, count) += factor * Eigen::Map<const Eigen::VectorXd>(values, count);
    return;
  }
  const int c = reduced_column_[column];
  if (c < 0) return;
  // Only the kept rows of [row, row + count): kept_residuals_ is ascending
  // (equations in order, then the conditions), so they are one run of it;
  // a quarter of the rows under a half-wave symmetry with a time reversal.
  const auto first = std::lower_bound(kept_residuals_.begin(), kept_residuals_.end(), row);
  for (auto it = first; it != kept_residuals_.end() && *it < row + count; ++it)
    (*J)(static_cast<int>(it - kept_residuals_.begin()), c) += factor * values[*it - row];
}

void CollocationResidual::ColumnTargets(int j, SpectralTransform::Targets* targets) {
  const char* kept = column_harmonics_.empty() ? nullptr : column_harmonics_[j].data();
  const int first = column_[j] >= 0 ? column_[j] : column_[definitions_[j].source];
  for (int c = 0; c < C_; ++c)
    column_target_[c] = !kept || kept[(c + 1) / 2] ? reduced_column_[first + c] : -1;
  targets->columns = column_target_.data();
}

bool CollocationResidual::AddSlotDirectly(size_t i, int s, bool constant, const Eigen::VectorXd& x,
                                          Eigen::MatrixXd* jacobian) {
  const int j = slots_[s].variable, derivative = slots_[s].derivative;
  const bool condensed = column_[j] < 0;
  if (transform_->num_angles() != 1 || derivative > 1 || (condensed && derivative && !constant)) return false;
  SpectralTransform::Targets targets;
  targets.rows = row_targets_[i].data();
  ColumnTargets(j, &targets);
  const double* rates = derivative ? rates_.data() : nullptr;
  if (condensed && derivative) {
    // v' = ratio D(w)^2 A: -ratio rate_k^2 on harmonic k's cos and sin alike.
    const double ratio = definitions_[j].ratio;
    for (int k = 1; k < basis_.size(); ++k)
      for (int c : {2 * k - 1, 2 * k})
        if (targets.rows[c] >= 0 && targets.columns[c] >= 0)
          (*jacobian)(targets.rows[c], targets.columns[c]) -= work_(0) * ratio * rates_[k] * rates_[k];
  } else {
    if (condensed) {
      // v's cos_k column lands on A's sin_k with ratio rate_k, its sin_k on
      // A's cos_k with -ratio rate_k, its mean nowhere (ChainColumn): the
      // derivative-style columns of E* diag(g') E D(ratio rates).
      chain_rates_.resize(basis_.size());
      for (int k = 0; k < basis_.size(); ++k) chain_rates_[k] = definitions_[j].ratio * rates_[k];
      rates = chain_rates_.data();
    }
    if (constant) {
      transform_->AddConstantMultiplicationTo(work_(0), rates, targets, *jacobian);
    } else {
      transform_->Analyze(work_.data());
      transform_->AddMultiplicationTo(rates, targets, *jacobian);
    }
  }
  if (condensed) {
    const Definition& d = definitions_[j];
    AddFrequencyColumns(i, j, x.data() + d.source * C_, d.ratio, derivative != 0, jacobian);
  }
  return true;
}

void CollocationResidual::AddFrequencyColumns(size_t i, int j, const double* A, double ratio, bool derivative,
                                              Eigen::MatrixXd* jacobian) {
  const CompiledEquation& eq = equations_[i];
  const int rows = C_ - (eq.balance_constant ? 0 : 1);
  for (int b = 0; b < basis_.num_bases(); ++b) {
    if (unknown_index_[b] < 0) continue;
    coef_(0) = 0;
    for (int k = 1; k < basis_.size(); ++k) {
      const double m = ratio * basis_.harmonic(k)[b];
      coef_(2 * k - 1) = m * A[2 * k];
      coef_(2 * k) = -m * A[2 * k - 1];
      if (derivative) {  // and D(rates) of it: cos_k <- rate_k sin_k, sin_k <- -rate_k cos_k
        const double cos_k = coef_(2 * k - 1);
        coef_(2 * k - 1) = rates_[k] * coef_(2 * k);
        coef_(2 * k) = -rates_[k] * cos_k;
      }
    }
    SynthesizeVariable(j, coef_.data(), term_.data());
    term_.array() *= work_.array();
    ProjectEquation(i, term_.data());
    AddToColumn(jacobian, FrequencyColumn(b), eq.first_row, rows, 1.0, proj_.data() + (C_ - rows));
  }
}

void CollocationResidual::AddVariableBlock(Eigen::MatrixXd* J, int row,
                                           const Eigen::Ref<const Eigen::MatrixXd>& block, int j,
                                           const Eigen::VectorXd& X) const {
  const int rows = static_cast<int>(block.rows());
  const char* kept = column_harmonics_.empty() ? nullptr : column_harmonics_[j].data();
  int column = 0;
  double factor = 0;
  for (int c = 0; c < C_; ++c)
    if ((!kept || kept[(c + 1) / 2]) && ChainColumn(j, c, rates_, &column, &factor))
      AddToColumn(J, column, row, rows, factor, block.col(c).data());
  if (column_[j] >= 0) return;
  // The definition's dependence on the unknown frequencies.
  const Definition& d = definitions_[j];
  const double* A = X.data() + d.source * C_;
  for (int b = 0; b < basis_.num_bases(); ++b) {
    if (unknown_index_[b] < 0) continue;
    for (int k = 1; k < basis_.size(); ++k) {
      const double m = d.ratio * basis_.harmonic(k)[b];
      if (m == 0 || (kept && !kept[k])) continue;
      AddToColumn(J, FrequencyColumn(b), row, rows, m * A[2 * k], block.col(2 * k - 1).data());
      AddToColumn(J, FrequencyColumn(b), row, rows, -m * A[2 * k - 1], block.col(2 * k).data());
    }
  }
}

template <class RowsOf>
void CollocationResidual::AddSparseBlock(std::vector<Eigen::Triplet<double>>* triplets,
                                         RowsOf rows_of, int first,
                                         const Eigen::Ref<const Eigen::MatrixXd>& block, int j) const {
  int column = 0;
  double factor = 0;
  for (long l = 0; l < block.cols(); ++l) {
    if (!ChainColumn(j, first + static_cast<int>(l), linearization_.rates, &column, &factor)) continue;
    const int c = reduced_column_[column];
    if (c < 0) continue;
    for (long i = 0; i < block.rows(); ++i) {
      const int full_row = rows_of(static_cast<int>(i));
      const int r = full_row >= 0 ? reduced_row_[full_row] : -1;
      if (r >= 0 && block(i, l) != 0) triplets->emplace_back(r, c, factor * block(i, l));
    }
  }
}

void CollocationResidual::PointValues(const Eigen::VectorXd& X, const std::vector<double>& rates,
                                      Eigen::VectorXd* z, Eigen::VectorXd* dz) const {
  z->resize(n_);
  dz->resize(n_);
  for (int j = 0; j < n_; ++j) {
    const double* c = X.data() + j * C_;
    (*z)(j) = c[0];
    (*dz)(j) = 0;
    for (int k = 1; k < basis_.size(); ++k) {
      (*z)(j) += c[2 * k - 1];
      (*dz)(j) += rates[k] * c[2 * k];
    }
  }
}

bool CollocationResidual::Linearize(const Eigen::VectorXd& x, Eigen::VectorXd* residual) {
  if (!Evaluate(x, residual, nullptr)) return false;
  // Evaluate sampled every slot at x (SampleSlots): keep the partials.
  Linearization& lin = linearization_;
  lin.X = Layout(x);
  lin.rates = rates_;
  lin.partials.assign(equations_.size(), {});
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    for (int slot : eq.slots) {
      lin.partials[i].emplace_back(M_);
      EvaluateSamples(eq, slot, lin.partials[i].back().data());
    }
  }
  lin.gz.clear();
  lin.gdz.clear();
  Eigen::VectorXd z, dz;
  PointValues(lin.X, lin.rates, &z, &dz);
  for (const auto& cond : problem_.conditions) {
    lin.gz.push_back(Eigen::VectorXd::Zero(n_));
    lin.gdz.push_back(Eigen::VectorXd::Zero(n_));
    cond.function(z, dz, &lin.gz.back(), &lin.gdz.back());
  }
  return true;
}

void CollocationResidual::ApplyJacobian(const Eigen::VectorXd& v, Eigen::VectorXd* product) {
  const Linearization& lin = linearization_;
  // v (reduced) -> the condensed layout -> dX on the full layout, with the
  // defined variables' tangent d(ratio D(w) A) = ratio (D(w) dA + D(dw) A).
  Eigen::VectorXd condensed = Eigen::VectorXd::Zero(full_unknowns_);
  for (int i = 0; i < num_unknowns_; ++i) condensed(kept_unknowns_.empty() ? i : kept_unknowns_[i]) = v(i);
  const int nu = layout_size_ - n_ * C_;
  Eigen::VectorXd dX = Eigen::VectorXd::Zero(layout_size_);
  dX.tail(nu) = condensed.tail(nu);
  std::vector<double> dw(problem_.frequencies.size(), 0.0), drates(basis_.size());
  for (int b = 0; b < basis_.num_bases(); ++b)
    if (unknown_index_[b] >= 0) dw[b] = dX(n_ * C_ + unknown_index_[b]);
  for (int k = 0; k < basis_.size(); ++k) drates[k] = basis_.Frequency(k, dw);
  // d(D(w) A) at coefficient pair k: rate dA + drate A, rotated.
  auto derivative_tangent = [&](const double* A, const double* dA, double ratio, double* out) {
    out[0] = 0;
    for (int k = 1; k < basis_.size(); ++k) {
      out[2 * k - 1] = ratio * (lin.rates[k] * dA[2 * k] + drates[k] * A[2 * k]);
      out[2 * k] = -ratio * (lin.rates[k] * dA[2 * k - 1] + drates[k] * A[2 * k - 1]);
    }
  };
  for (int j = 0; j < n_; ++j)
    if (column_[j] >= 0) dX.segment(j * C_, C_) = condensed.segment(column_[j], C_);
  for (int j = 0; j < n_; ++j) {
    const Definition& d = definitions_[j];
    if (d.source >= 0)
      derivative_tangent(lin.X.data() + d.source * C_, dX.data() + d.source * C_, d.ratio,
                         dX.data() + j * C_);
  }
  for (size_t s = 0; s < slots_.size(); ++s) {
    const int j = slots_[s].variable;
    if (slots_[s].derivative == 0) {
      transform_->Synthesize(dX.data() + j * C_, tangent_samples_[s].data());
    } else {
      derivative_tangent(lin.X.data() + j * C_, dX.data() + j * C_, 1.0, coef_.data());
      transform_->Synthesize(coef_.data(), tangent_samples_[s].data());
    }
  }
  Eigen::VectorXd& full = tangent_residual_;
  full.setZero(full_residuals_);
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    work_.setZero();
    for (size_t q = 0; q < eq.slots.size(); ++q)
      work_.array() += lin.partials[i][q].array() * tangent_samples_[eq.slots[q]].array();
    transform_->Project(work_.data(), proj_.data());
    const int rows = eq.balance_constant ? C_ : C_ - 1;
    full.segment(eq.first_row, rows) = proj_.tail(rows);
  }
  if (!problem_.conditions.empty()) {
    Eigen::VectorXd z, dz, z_w, dz_w;
    PointValues(dX, lin.rates, &z, &dz);
    PointValues(lin.X, drates, &z_w, &dz_w);
    dz += dz_w;
    int row = full_residuals_ - static_cast<int>(problem_.conditions.size());
    for (size_t c = 0; c < problem_.conditions.size(); ++c)
      full(row++) = lin.gz[c].dot(z) + lin.gdz[c].dot(dz);
  }
  product->resize(num_residuals_);
  for (int r = 0; r < num_residuals_; ++r) (*product)(r) = full(kept_residuals_.empty() ? r : kept_residuals_[r]);
}

void CollocationResidual::SparseJacobian(double coupling, Eigen::SparseMatrix<double>* jacobian) {
  const Linearization& lin = linearization_;
  const int K = basis_.size();
  const int coupled = coupling >= 1 ? K : std::clamp(static_cast<int>(std::ceil(coupling * K)), 1, K);
  std::vector<Eigen::Triplet<double>> triplets;
  const int low_size = 2 * coupled - 1;
  Eigen::MatrixXd low(low_size, low_size);
  Eigen::Matrix2d diagonal;
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    const int skip = eq.balance_constant ? 0 : 1;
    // Coefficient c of the equation is residual row first_row + c - skip.
    auto rows_from = [&](int first) {
      return [&eq, skip, first](int r) { return first + r < skip ? -1 : eq.first_row + first + r - skip; };
    };
    // The coupled blocks summed per unknown variable first (a condensed
    // variable's slots land on its source's), then stored once: a third of
    // the triplets for x, x', x'' of one variable.
    std::map<int, Eigen::MatrixXd> coupled_blocks;
    for (size_t q = 0; q < eq.slots.size(); ++q) {
      const SlotInfo& slot = slots_[eq.slots[q]];
      transform_->Analyze(lin.partials[i][q].data());
      const double* rate = slot.derivative ? lin.rates.data() : nullptr;
      low.setZero();
      transform_->AddMultiplicationBlock(1.0, rate, 0, coupled, low);
      const int source = definitions_[slot.variable].source >= 0 ? definitions_[slot.variable].source
                                                                 : slot.variable;
      auto [it, fresh] = coupled_blocks.try_emplace(source);
      if (fresh) it->second.setZero(low_size, low_size);
      int column = 0;
      double factor = 0;
      for (int c = 0; c < low_size; ++c)
        if (ChainColumn(slot.variable, c, lin.rates, &column, &factor) && column - column_[source] < low_size)
          it->second.col(column - column_[source]) += factor * low.col(c);
      for (int k = coupled; k < K; ++k) {
        diagonal.setZero();
        transform_->AddMultiplicationBlock(1.0, rate, k, k + 1, diagonal);
        AddSparseBlock(&triplets, rows_from(2 * k - 1), 2 * k - 1, diagonal, slot.variable);
      }
    }
    for (const auto& [source, block] : coupled_blocks)
      AddSparseBlock(&triplets, rows_from(0), 0, block, source);
  }
  // Point conditions: rows of g_z (z(0) = a_0 + sum a_k) and g_z' (z'(0) =
  // sum rate_k b_k) per variable.
  const int first_condition = full_residuals_ - static_cast<int>(problem_.conditions.size());
  Eigen::MatrixXd g(1, C_);
  for (size_t c = 0; c < problem_.conditions.size(); ++c)
    for (int j = 0; j < n_; ++j) {
      const double gz = lin.gz[c](j), gdz = lin.gdz[c](j);
      if (gz == 0 && gdz == 0) continue;
      g(0, 0) = gz;
      for (int k = 1; k < K; ++k) {
        g(0, 2 * k - 1) = gz;
        g(0, 2 * k) = gdz * lin.rates[k];
      }
      const int row = first_condition + static_cast<int>(c);
      AddSparseBlock(&triplets, [row](int) { return row; }, 0, g, j);
    }
  // The frequency columns, exact: J e_w by a product (they are dense).
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(num_unknowns_), column;
  for (int b = 0; b < basis_.num_bases(); ++b) {
    if (unknown_index_[b] < 0) continue;
    const int c = reduced_column_[FrequencyColumn(b)];
    unit(c) = 1;
    ApplyJacobian(unit, &column);
    unit(c) = 0;
    for (int r = 0; r < num_residuals_; ++r)
      if (column(r) != 0) triplets.emplace_back(r, c, column(r));
  }
  jacobian->resize(num_residuals_, num_unknowns_);
  jacobian->setFromTriplets(triplets.begin(), triplets.end());
}

void CollocationResidual::Frequencies(const Eigen::VectorXd& x, std::vector<double>* w) const {
  *w = problem_.frequencies;
  for (int b = 0; b < basis_.num_bases(); ++b)
    if (unknown_index_[b] >= 0) (*w)[b] = x(n_ * C_ + unknown_index_[b]);
}

Eigen::VectorXd CollocationResidual::Pack(const Eigen::MatrixXd& coefficients,
                                          const std::vector<double>& frequencies) const {
  // The layout, then condensed, then reduced by the symmetries.
  Eigen::VectorXd x(layout_size_);
  for (int j = 0; j < n_; ++j) x.segment(j * C_, C_) = coefficients.row(j).transpose();
  for (int b = 0; b < basis_.num_bases(); ++b)
    if (unknown_index_[b] >= 0) x(n_ * C_ + unknown_index_[b]) = frequencies[b];
  if (num_condensed_ > 0) {
    Eigen::VectorXd condensed(full_unknowns_);
    for (int j = 0; j < n_; ++j)
      if (column_[j] >= 0) condensed.segment(column_[j], C_) = x.segment(j * C_, C_);
    condensed.tail(full_unknowns_ - frequency_column_) = x.tail(layout_size_ - n_ * C_);
    x = std::move(condensed);
  }
  if (kept_unknowns_.empty()) return x;
  Eigen::VectorXd reduced(num_unknowns_);
  for (int i = 0; i < num_unknowns_; ++i) reduced(i) = x(kept_unknowns_[i]);
  return reduced;
}

void CollocationResidual::Unpack(const Eigen::VectorXd& x, Eigen::MatrixXd* coefficients,
                                 std::vector<double>* frequencies) const {
  // Reduced -> condensed (zeros where a symmetry excludes) -> the layout.
  Eigen::VectorXd condensed = Eigen::VectorXd::Zero(full_unknowns_);
  if (kept_unknowns_.empty()) condensed = x;
  else
    for (int i = 0; i < num_unknowns_; ++i) condensed(kept_unknowns_[i]) = x(i);
  Eigen::VectorXd full = Eigen::VectorXd::Zero(layout_size_);
  if (num_condensed_ > 0) Expand(condensed, &full);
  else full = condensed;
  coefficients->resize(n_, C_);
  for (int j = 0; j < n_; ++j) coefficients->row(j) = full.segment(j * C_, C_).transpose();
  Frequencies(full, frequencies);
}

void CollocationResidual::EvaluatePointwise(const std::vector<double>& w) {
  for (const CompiledEquation& eq : equations_) {
    if (!eq.pointwise) continue;
    const size_t n = eq.slots.size();
    pointwise_in_.resize(1 + n + w.size());
    pointwise_out_.resize(1 + n);
    Eigen::MatrixXd& values = pointwise_values_[eq.pointwise_index];
    if (eq.pointwise->evaluate_many) {
      // Every sample in one call: columns t, the slots, the frequencies.
      Eigen::MatrixXd& in = pointwise_many_in_;
      in.resize(M_, static_cast<long>(1 + n + w.size()));
      for (long t = 0; t < M_; ++t) in(t, 0) = sample_phase_[t] / w[0];
      for (size_t i = 0; i < n; ++i) in.col(static_cast<long>(1 + i)) = slot_samples_[eq.slots[i]];
      for (size_t b = 0; b < w.size(); ++b) in.col(static_cast<long>(1 + n + b)).setConstant(w[b]);
      eq.pointwise->evaluate_many(M_, in.data(), M_, values.data(), values.rows());
      continue;
    }
    for (size_t b = 0; b < w.size(); ++b) pointwise_in_[1 + n + b] = w[b];
    for (long t = 0; t < M_; ++t) {
      // t = theta_1 / w_1: explicit time only in models of one known base
      // (the model layer refuses the others).
      pointwise_in_[0] = sample_phase_[t] / w[0];
      for (size_t i = 0; i < n; ++i) pointwise_in_[1 + i] = slot_samples_[eq.slots[i]](t);
      eq.pointwise->evaluate(pointwise_in_.data(), pointwise_out_.data());
      for (size_t i = 0; i <= n; ++i) values(t, static_cast<long>(i)) = pointwise_out_[i];
    }
  }
}

void CollocationResidual::EvaluateSamples(const CompiledEquation& eq, int slot, double* out) const {
  Eigen::Map<Eigen::VectorXd> result(out, M_);
  if (eq.pointwise) {
    const Eigen::MatrixXd& values = pointwise_values_[eq.pointwise_index];
    if (slot < 0) {
      result = values.col(0);
      return;
    }
    result.setZero();  // a slot listed twice adds up
    for (size_t i = 0; i < eq.slots.size(); ++i)
      if (eq.slots[i] == slot) result += values.col(static_cast<long>(i) + 1);
    return;
  }
  // Plain loops over the M samples: at the Monte Carlo's M = 7 and 14 each
  // Eigen vector operation cost more in set-up than in arithmetic (~480
  // instructions a call for the Duffing's cubic term, ~340 with the loops).
  // The same products in the same order, so the same bits.
  std::fill(out, out + M_, 0.0);
  double* term = const_cast<Eigen::VectorXd&>(term_).data();
  for (const auto& t : eq.terms) {
    double c = t.coefficient;
    int differentiated = -1;
    if (slot >= 0) {
      for (size_t f = 0; f < t.factors.size(); ++f)
        if (t.factors[f].first == slot) differentiated = static_cast<int>(f);
      if (differentiated < 0) continue;
      c *= t.factors[differentiated].second;
    }
    if (t.time >= 0) {
      const double* time = time_samples_[t.time].data();
      for (int i = 0; i < M_; ++i) term[i] = c * time[i];
    } else {
      std::fill(term, term + M_, c);
    }
    for (size_t f = 0; f < t.factors.size(); ++f) {
      int power = t.factors[f].second - (static_cast<int>(f) == differentiated ? 1 : 0);
      const double* z = slot_samples_[t.factors[f].first].data();
      for (int p = 0; p < power; ++p)
        for (int i = 0; i < M_; ++i) term[i] *= z[i];
    }
    for (int i = 0; i < M_; ++i) out[i] += term[i];
  }
}

bool CollocationResidual::SamplesAdmissible() const {
  double largest = 0;
  for (const Eigen::VectorXd& z : slot_samples_) largest = std::max(largest, z.cwiseAbs().maxCoeff());
  return largest <= overflow_bound_;
}

void CollocationResidual::ProjectEquation(size_t i, const double* samples) {
  // Rows a symmetry drops: zeros (their harmonics vanish on symmetric x).
  if (row_coefficients_.empty()) return transform_->Project(samples, proj_.data());
  proj_.setZero();
  transform_->ProjectSome(samples, row_coefficients_[i], proj_.data());
}

void CollocationResidual::BuildSampledMaps() {
  maps_.frequencies = problem_.frequencies;
  // Column u of A_s: the samples of slot s for x = e_u, by the general path.
  maps_.slot.assign(slots_.size(), Eigen::MatrixXd(M_, num_unknowns_));
  Eigen::VectorXd unit = Eigen::VectorXd::Zero(num_unknowns_);
  for (int u = 0; u < num_unknowns_; ++u) {
    unit(u) = 1;
    SampleSlots(Layout(unit));
    unit(u) = 0;
    for (size_t s = 0; s < slots_.size(); ++s) maps_.slot[s].col(u) = slot_samples_[s];
  }
  // Column t of Q_i: equation i's kept rows for the unit sample e_t.
  const size_t E = equations_.size();
  maps_.equation.assign(E, Eigen::MatrixXd());
  maps_.equation_row.assign(E, 0);
  Eigen::VectorXd sample = Eigen::VectorXd::Zero(M_);
  for (size_t i = 0; i < E; ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    const int skip = eq.balance_constant ? 0 : 1;
    std::vector<int> kept;  // (reduced row, coefficient); reduced rows of an equation are consecutive
    for (int c = skip; c < C_; ++c)
      if (reduced_row_[eq.first_row + c - skip] >= 0) kept.push_back(c);
    Eigen::MatrixXd& Q = maps_.equation[i];
    Q.resize(static_cast<long>(kept.size()), M_);
    maps_.equation_row[i] = kept.empty() ? 0 : reduced_row_[eq.first_row + kept[0] - skip];
    for (long t = 0; t < M_; ++t) {
      sample(t) = 1;
      ProjectEquation(i, sample.data());
      sample(t) = 0;
      for (size_t r = 0; r < kept.size(); ++r) Q(static_cast<long>(r), t) = proj_(kept[r]);
    }
  }
  BuildAffineMaps();
}

void CollocationResidual::BuildAffineMaps() {
  // Terms of degree <= 1 (the linear stiffness, damping, inertia, forcing;
  // time-varying coefficients too) give rows affine in x: Q_i g(A x) of them
  // is L_i x + b_i, made here once (METHOD.md s.21). Only the nonlinear terms
  // are sampled at each evaluation, and only their slots: the forced
  // Duffing's x'' + c x' + k x - F cos wt leaves x^3, one slot of three.
  const size_t E = equations_.size();
  maps_.linear.assign(E, Eigen::MatrixXd());
  maps_.constant.assign(E, Eigen::VectorXd());
  maps_.nonlinear.assign(E, CompiledEquation{});
  maps_.outer.assign(E, {});
  std::vector<char> nonlinear_slot(slots_.size(), 0);
  for (size_t i = 0; i < E; ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;
    CompiledEquation affine = eq, nonlinear = eq;
    affine.terms.clear();
    nonlinear.terms.clear();
    for (const CompiledTerm& t : eq.terms) {
      int degree = 0;
      for (const auto& factor : t.factors) degree += factor.second;
      (degree <= 1 ? affine : nonlinear).terms.push_back(t);
    }
    nonlinear.slots.clear();
    for (int s : eq.slots) {
      bool used = false;
      for (const CompiledTerm& t : nonlinear.terms)
        for (const auto& factor : t.factors) used = used || factor.first == s;
      if (used) nonlinear.slots.push_back(s), nonlinear_slot[s] = 1;
    }
    const Eigen::MatrixXd& Q = maps_.equation[i];
    // b_i: the affine terms at x = 0; L_i: their partials (constant) on A_s.
    for (Eigen::VectorXd& z : slot_samples_) z.setZero();
    EvaluateSamples(affine, -1, work_.data());
    maps_.constant[i] = Q * work_;
    maps_.weighted.setZero(M_, num_unknowns_);
    for (int s : eq.slots) {
      EvaluateSamples(affine, s, work_.data());
      maps_.weighted += work_.asDiagonal() * maps_.slot[s];
    }
    maps_.linear[i] = Q * maps_.weighted;
    maps_.outer[i].clear();
    for (int s : nonlinear.slots) {
      const Eigen::MatrixXd& A = maps_.slot[s];
      Eigen::MatrixXd T(Q.rows() * num_unknowns_, M_);
      for (long t = 0; t < M_; ++t)
        for (long u = 0; u < num_unknowns_; ++u) T.col(t).segment(u * Q.rows(), Q.rows()) = Q.col(t) * A(t, u);
      maps_.outer[i].push_back(std::move(T));
    }
    maps_.nonlinear[i] = std::move(nonlinear);
  }
  maps_.nonlinear_slots.clear();
  for (size_t s = 0; s < slots_.size(); ++s)
    if (nonlinear_slot[s]) maps_.nonlinear_slots.push_back(static_cast<int>(s));
  const long S = static_cast<long>(maps_.nonlinear_slots.size());
  maps_.stacked.resize(S * M_, num_unknowns_);
  for (long k = 0; k < S; ++k) maps_.stacked.middleRows(k * M_, M_) = maps_.slot[maps_.nonlinear_slots[k]];
}

bool CollocationResidual::EvaluateSampled(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                                          Eigen::MatrixXd* jacobian) {
  if (maps_.frequencies != problem_.frequencies) BuildSampledMaps();
  // The nonlinear terms' slots, in one product; only they can overflow.
  maps_.stacked_samples.noalias() = maps_.stacked * x;
  if (maps_.stacked_samples.size() && !(maps_.stacked_samples.cwiseAbs().maxCoeff() <= overflow_bound_)) {
    residual->setConstant(num_residuals_, INFINITY);
    return false;
  }
  for (size_t k = 0; k < maps_.nonlinear_slots.size(); ++k)
    slot_samples_[maps_.nonlinear_slots[k]] = maps_.stacked_samples.segment(static_cast<long>(k) * M_, M_);
  residual->setZero(num_residuals_);
  if (jacobian) jacobian->setZero(num_residuals_, num_unknowns_);
  for (size_t i = 0; i < equations_.size(); ++i) {
    if (equations_[i].first_row < 0) continue;
    const CompiledEquation& eq = maps_.nonlinear[i];
    const Eigen::MatrixXd& Q = maps_.equation[i];
    const long row = maps_.equation_row[i], rows = Q.rows();
    auto F = residual->segment(row, rows);
    F = maps_.constant[i];
    F.noalias() += maps_.linear[i] * x;
    if (jacobian) jacobian->middleRows(row, rows) = maps_.linear[i];
    if (eq.terms.empty()) continue;
    EvaluateSamples(eq, -1, work_.data());
    if (!work_.allFinite()) return false;
    F.noalias() += Q * work_;
    if (!jacobian) continue;
    maps_.flat.setZero(rows * num_unknowns_);
    for (size_t k = 0; k < eq.slots.size(); ++k) {
      EvaluateSamples(eq, eq.slots[k], work_.data());
      maps_.flat.noalias() += maps_.outer[i][k] * work_;
    }
    jacobian->middleRows(row, rows) += Eigen::Map<const Eigen::MatrixXd>(maps_.flat.data(), rows, num_unknowns_);
  }
  return residual->allFinite() && (!jacobian || jacobian->allFinite());
}

bool CollocationResidual::Evaluate(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                                   Eigen::MatrixXd* jacobian) {
  if (sampled_maps_eligible_) return EvaluateSampled(x, residual, jacobian);
  const Eigen::VectorXd& X = Layout(x);
  if (kept_unknowns_.empty()) return EvaluateFull(X, residual, jacobian);
  const bool ok = EvaluateFull(X, &full_residual_, jacobian);
  residual->resize(num_residuals_);
  for (int r = 0; r < num_residuals_; ++r) (*residual)(r) = full_residual_(kept_residuals_[r]);
  return ok;
}

void CollocationResidual::SynthesizeVariable(int j, const double* coefficients, double* samples) {
  // The coefficients come through Layout: zero where a symmetry drops one.
  if (column_coefficients_.empty())
    transform_->Synthesize(coefficients, samples);
  else
    transform_->SynthesizeSome(coefficients, column_coefficients_[j], samples);
}

void CollocationResidual::SampleSlots(const Eigen::VectorXd& x) {
  std::vector<double> w;
  Frequencies(x, &w);
  for (int k = 0; k < basis_.size(); ++k) rates_[k] = basis_.Frequency(k, w);
  for (size_t s = 0; s < slots_.size(); ++s) {
    const int j = slots_[s].variable;
    const double* X = x.data() + j * C_;
    const double* coefficients = X;
    if (slots_[s].derivative != 0) {
      coef_(0) = 0;
      for (int k = 1; k < basis_.size(); ++k) {
        coef_(2 * k - 1) = rates_[k] * X[2 * k];
        coef_(2 * k) = -rates_[k] * X[2 * k - 1];
      }
      coefficients = coef_.data();
    }
    SynthesizeVariable(j, coefficients, slot_samples_[s].data());
  }
  if (!pointwise_values_.empty()) EvaluatePointwise(w);
}

const Eigen::VectorXd& CollocationResidual::Full(const Eigen::VectorXd& x) {
  if (kept_unknowns_.empty()) return x;
  for (int i = 0; i < num_unknowns_; ++i) full_x_(kept_unknowns_[i]) = x(i);
  return full_x_;
}

const Eigen::VectorXd& CollocationResidual::Layout(const Eigen::VectorXd& x) {
  const Eigen::VectorXd& condensed = Full(x);
  if (num_condensed_ == 0) return condensed;
  Expand(condensed, &expanded_);
  return expanded_;
}

// Every (equation, slot) block E* diag(dg_i/dz_s) E of the linearisation at
// x (no frequency rates), handed to add(equation, slot, block) in turn.
template <typename AddBlock>
void CollocationResidual::ForEachBlock(const Eigen::VectorXd& x, AddBlock add) {
  SampleSlots(Layout(x));
  for (size_t i = 0; i < equations_.size(); ++i)
    for (int s : equations_[i].slots) {
      EvaluateSamples(equations_[i], s, work_.data());
      transform_->Analyze(work_.data());
      block_.setZero(C_, C_);
      transform_->AddMultiplicationMatrix(1.0, nullptr, block_);
      add(static_cast<int>(i), slots_[s], block_);
    }
}

void CollocationResidual::LinearizationParts(const Eigen::VectorXd& x, Eigen::MatrixXd* value_part,
                                             Eigen::MatrixXd* derivative_part) {
  value_part->setZero(n_ * C_, n_ * C_);
  derivative_part->setZero(n_ * C_, n_ * C_);
  ForEachBlock(x, [&](int i, const SlotInfo& slot, const Eigen::MatrixXd& block) {
    Eigen::MatrixXd& part = slot.derivative ? *derivative_part : *value_part;
    part.block(static_cast<long>(i) * C_, slot.variable * C_, C_, C_) += block;
  });
}

bool CollocationResidual::SampledPartials(const Eigen::VectorXd& x, Eigen::MatrixXd* value,
                                         Eigen::MatrixXd* derivative) {
  if (static_cast<int>(equations_.size()) != n_) return false;
  for (const SlotInfo& slot : slots_)
    if (slot.derivative > 1) return false;
  SampleSlots(Layout(x));
  value->setZero(M_, n_ * n_);
  derivative->setZero(M_, n_ * n_);
  for (int i = 0; i < n_; ++i)
    for (int s : equations_[i].slots) {
      EvaluateSamples(equations_[i], s, work_.data());
      Eigen::MatrixXd& part = slots_[s].derivative ? *derivative : *value;
      part.col(i * n_ + slots_[s].variable) += work_;
    }
  return true;
}

void CollocationResidual::LinearizationParts(const Eigen::VectorXd& x,
                                             Eigen::SparseMatrix<double>* value_part,
                                             Eigen::SparseMatrix<double>* derivative_part) {
  std::vector<Eigen::Triplet<double>> value, derivative;
  ForEachBlock(x, [&](int i, const SlotInfo& slot, const Eigen::MatrixXd& block) {
    const double floor = 1e-14 * block.cwiseAbs().maxCoeff();
    auto& part = slot.derivative ? derivative : value;
    for (int l = 0; l < C_; ++l)
      for (int k = 0; k < C_; ++k)
        if (std::abs(block(k, l)) > floor) part.emplace_back(i * C_ + k, slot.variable * C_ + l, block(k, l));
  });
  value_part->resize(n_ * C_, n_ * C_);
  derivative_part->resize(n_ * C_, n_ * C_);
  value_part->setFromTriplets(value.begin(), value.end());
  derivative_part->setFromTriplets(derivative.begin(), derivative.end());
}

// The general path of one slot's block: the C x C block E* diag(g') E (D)
// formed, then added through AddVariableBlock (where AddSlotDirectly
// cannot).
void CollocationResidual::AddSlotThroughBlock(int i, int s, const double* rates, bool constant,
                                              const Eigen::VectorXd& x, Eigen::MatrixXd* jacobian) {
  const CompiledEquation& eq = equations_[i];
  const int j = slots_[s].variable;
  const int rows = C_ - (eq.balance_constant ? 0 : 1);
  // AddVariableBlock reads the kept harmonics' columns only: those are
  // all a reduced J needs cleared (a constant partial writes them all).
  if (constant || column_harmonics_.empty()) {
    block_.setZero(C_, C_);
  } else {
    block_.resize(C_, C_);
    for (int c : column_coefficients_[j]) block_.col(c).setZero();
  }
  if (constant) {
    transform_->AddConstantMultiplication(work_(0), rates, block_);  // a linear term
  } else {
    transform_->Analyze(work_.data());
    // Only the entries the symmetry reduction keeps (METHOD.md s.13).
    transform_->AddMultiplicationMatrix(1.0, rates, block_,
                                        row_harmonics_.empty() ? nullptr : row_harmonics_[i].data(),
                                        column_harmonics_.empty() ? nullptr : column_harmonics_[j].data());
  }
  AddVariableBlock(jacobian, eq.first_row, block_.bottomRows(rows), j, x);
}

bool CollocationResidual::EvaluateFull(const Eigen::VectorXd& x, Eigen::VectorXd* residual,
                                       Eigen::MatrixXd* jacobian) {
  SampleSlots(x);
  // Samples so large that a term of the system's degree overflows are no
  // admissible point (a guess at 1.8e308: Rayleigh-Plesset without gas
  // pressure). FFTW's butterflies happened to turn them into inf; the dense
  // transforms do not, so it is said here on purpose.
  if (!SamplesAdmissible()) {
    residual->setConstant(full_residuals_, INFINITY);
    return false;
  }

  residual->resize(full_residuals_);
  if (jacobian) jacobian->setZero(num_residuals_, num_unknowns_);
  for (size_t i = 0; i < equations_.size(); ++i) {
    const CompiledEquation& eq = equations_[i];
    if (eq.first_row < 0) continue;  // condensed: satisfied by construction
    const int skip = eq.balance_constant ? 0 : 1;
    const int rows = C_ - skip;
    EvaluateSamples(eq, -1, work_.data());
    if (!work_.allFinite()) return false;
    ProjectEquation(i, work_.data());
    residual->segment(eq.first_row, rows) = proj_.tail(rows);
    if (!jacobian) continue;
    for (int s : eq.slots) {
      EvaluateSamples(eq, s, work_.data());
      const int j = slots_[s].variable;
      const double* rates = slots_[s].derivative ? rates_.data() : nullptr;
      const bool constant = (work_.array() == work_(0)).all();
      if (!AddSlotDirectly(i, s, constant, x, jacobian))
        AddSlotThroughBlock(static_cast<int>(i), s, rates, constant, x, jacobian);
      // z' = sum_b w_b d z / d theta_b: a column per unknown frequency.
      if (slots_[s].derivative) AddFrequencyColumns(i, j, x.data() + j * C_, 1.0, false, jacobian);
    }
  }

  // Point conditions at t = 0: z(0) = a_0 + sum a_k, z'(0) = sum rate_k b_k.
  if (!problem_.conditions.empty()) {
    Eigen::VectorXd z, dz, gz(n_), gdz(n_);
    PointValues(x, rates_, &z, &dz);
    int row = full_residuals_ - static_cast<int>(problem_.conditions.size());
    for (const auto& cond : problem_.conditions) {
      gz.setZero();
      gdz.setZero();
      (*residual)(row) = cond.function(z, dz, jacobian ? &gz : nullptr, jacobian ? &gdz : nullptr);
      if (jacobian) {
        for (int j = 0; j < n_; ++j) {
          if (gz(j) == 0 && gdz(j) == 0) continue;
          Eigen::MatrixXd g = Eigen::MatrixXd::Zero(1, C_);
          g(0, 0) = gz(j);
          for (int k = 1; k < basis_.size(); ++k) {
            g(0, 2 * k - 1) = gz(j);
            g(0, 2 * k) = gdz(j) * rates_[k];
          }
          AddVariableBlock(jacobian, row, g, j, x);
          if (gdz(j) == 0) continue;
          for (int b = 0; b < basis_.num_bases(); ++b) {
            if (unknown_index_[b] < 0) continue;
            double d = 0;
            for (int k = 1; k < basis_.size(); ++k) d += basis_.harmonic(k)[b] * x(j * C_ + 2 * k);
            AddToColumn(jacobian, FrequencyColumn(b), row, 1, gdz(j), &d);
          }
        }
      }
      ++row;
    }
  }
  return residual->allFinite() && (!jacobian || jacobian->allFinite());
}

}  // namespace rmhb
