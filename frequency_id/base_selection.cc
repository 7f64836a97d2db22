#include "frequency_id/base_selection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numeric>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Core>

namespace rmhb::frequency_id {
namespace {

constexpr int kMaxRank = 3;
using Label = std::array<int, kMaxRank>;
// Integer matrices are kept 3x3, padded with the identity below rank 3, so
// one determinant and one inverse serve every rank.
using IntMatrix = std::array<std::array<int, kMaxRank>, kMaxRank>;

struct Basis {
  int rank = 0;
  int num_known = 0;  // the first num_known entries are known frequencies
  std::array<double, kMaxRank> value{};
  std::array<double, kMaxRank> sigma{};
};

struct Score {
  double unexplained_energy = 0.0;
  int num_unexplained = 0;
  double decay_misfit = 0.0;
  double weighted_norm = 0.0;
  int bases_as_lines = 0;
  double base_line_energy = 0.0;
  int max_entry = 0;
};

struct Evaluated {
  bool valid = false;
  Basis basis;
  std::vector<Label> labels;
  std::vector<char> explained;
  Score score;
};

// a < b beyond a relative tolerance; the same lattice scored from different
// candidate sets must tie exactly enough to reach the next criterion.
bool ClearlyLess(double a, double b) { return a < b - 1e-9 * (1.0 + std::abs(b)); }

bool Better(const Score& a, const Score& b, double energy_tolerance) {
  if (a.unexplained_energy < b.unexplained_energy - energy_tolerance) return true;
  if (b.unexplained_energy < a.unexplained_energy - energy_tolerance) return false;
  if (a.num_unexplained != b.num_unexplained) return a.num_unexplained < b.num_unexplained;
  if (ClearlyLess(a.decay_misfit, b.decay_misfit)) return true;
  if (ClearlyLess(b.decay_misfit, a.decay_misfit)) return false;
  if (ClearlyLess(a.weighted_norm, b.weighted_norm)) return true;
  if (ClearlyLess(b.weighted_norm, a.weighted_norm)) return false;
  if (a.bases_as_lines != b.bases_as_lines) return a.bases_as_lines > b.bases_as_lines;
  if (a.base_line_energy != b.base_line_energy) return a.base_line_energy > b.base_line_energy;
  return a.max_entry < b.max_entry;
}

// Huber loss of the robust fit
//   log A_k = c - sum_i s_i |l_ki|
// over the explained lines: how well "amplitudes fall geometrically with
// each entry of the label" describes the spectrum in these coordinates.
// Huber (quadratic within a factor e of the fit, linear beyond) so that a
// few resonantly enhanced or accidentally weak lines cannot outvote the
// trend; solved by iteratively reweighted least squares.
double DecayMisfit(const std::vector<LineEstimate>& lines, const std::vector<Label>& labels,
                   const std::vector<char>& explained, int rank) {
  constexpr double kHuberThreshold = 1.0;
  constexpr int kMaxIterations = 30;
  int count = 0;
  for (char e : explained) count += e ? 1 : 0;
  // With barely more lines than parameters any coordinates fit some decay:
  // the criterion needs as many spare lines as it has parameters.
  if (count < 2 * (rank + 1)) return 0.0;
  const int params = rank + 1;
  Eigen::MatrixXd design(count, params);
  Eigen::VectorXd log_amplitude(count);
  int row = 0;
  for (std::size_t k = 0; k < lines.size(); ++k) {
    if (!explained[k]) continue;
    design(row, 0) = 1.0;
    for (int i = 0; i < rank; ++i) design(row, i + 1) = std::abs(labels[k][i]);
    const double amplitude = std::sqrt(2.0 * lines[k].energy);
    log_amplitude(row) = std::log(std::max(amplitude, std::numeric_limits<double>::min()));
    ++row;
  }
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(count);
  Eigen::VectorXd residual(count);
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    Eigen::MatrixXd normal = design.transpose() * weights.asDiagonal() * design;
    // A base no line uses leaves a zero column: the ridge keeps the
    // system solvable without changing the fit of the columns in use.
    normal.diagonal().array() += 1e-12 * (1.0 + normal.diagonal().maxCoeff());
    const Eigen::VectorXd coefficients =
        normal.ldlt().solve(design.transpose() * weights.asDiagonal() * log_amplitude);
    residual = log_amplitude - design * coefficients;
    Eigen::VectorXd next(count);
    for (int i = 0; i < count; ++i) {
      const double r = std::abs(residual(i));
      next(i) = r <= kHuberThreshold ? 1.0 : kHuberThreshold / r;
    }
    const bool settled = (next - weights).cwiseAbs().maxCoeff() < 1e-9;
    weights = next;
    if (settled) break;
  }
  double loss = 0.0;
  for (int i = 0; i < count; ++i) {
    const double r = std::abs(residual(i));
    loss += r <= kHuberThreshold ? 0.5 * r * r : kHuberThreshold * (r - 0.5 * kHuberThreshold);
  }
  return loss;
}

int Determinant(const IntMatrix& m) {
  return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Inverse of a unimodular matrix: the adjugate times det = +-1.
IntMatrix UnimodularInverse(const IntMatrix& m) {
  const int det = Determinant(m);
  IntMatrix inv{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      inv[i][j] = det * (m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0]);
    }
  }
  return inv;
}

struct Unimodular {
  IntMatrix u;
  IntMatrix inverse;
};

// All unimodular U of the given rank that keep the known bases (rows
// 0 .. num_known-1 are unit rows) and have free entries in [-e, e]; e shrinks
// with rank to keep the enumeration small.
std::vector<Unimodular> UnimodularTransforms(int rank, int num_known) {
  const int e = rank == 2 ? 2 : 1;
  std::vector<std::pair<int, int>> free_entries;
  for (int i = num_known; i < rank; ++i) {
    for (int j = 0; j < rank; ++j) free_entries.emplace_back(i, j);
  }
  std::vector<Unimodular> result;
  IntMatrix u{};
  for (int i = 0; i < 3; ++i) u[i][i] = 1;
  const int values = 2 * e + 1;
  long total = 1;
  for (std::size_t k = 0; k < free_entries.size(); ++k) total *= values;
  for (long code = 0; code < total; ++code) {
    long rest = code;
    for (const auto& [i, j] : free_entries) {
      u[i][j] = static_cast<int>(rest % values) - e;
      rest /= values;
    }
    const int det = Determinant(u);
    if (det == 1 || det == -1) result.push_back({u, UnimodularInverse(u)});
  }
  return result;
}

int LabelBound(int rank, const BaseSelectionOptions& options) {
  return rank == 1 ? std::max(options.max_order, options.max_harmonic) : options.max_order;
}

double LabelTolerance(const LineEstimate& line, const Basis& basis, const Label& label,
                      const BaseSelectionOptions& options) {
  double variance = line.uncertainty * line.uncertainty;
  double scale = line.frequency;
  for (int i = 0; i < basis.rank; ++i) {
    const double term = label[i] * basis.sigma[i];
    variance += term * term;
    scale = std::max(scale, basis.value[i]);
  }
  return options.tolerance_factor * std::sqrt(variance) + options.relative_tolerance_floor * scale;
}

double LatticeValue(const Basis& basis, const Label& label) {
  double value = 0.0;
  for (int i = 0; i < basis.rank; ++i) value += label[i] * basis.value[i];
  return value;
}

// The label of the lattice point nearest to the line (relative to its
// tolerance), with every |entry| <= bound; false if none is within tolerance.
bool NearestLabel(const LineEstimate& line, const Basis& basis, int bound,
                  const BaseSelectionOptions& options, Label* label) {
  const int n_bound = basis.rank >= 2 ? bound : 0;
  const int p_bound = basis.rank >= 3 ? bound : 0;
  double best_ratio = std::numeric_limits<double>::infinity();
  bool found = false;
  for (int p = -p_bound; p <= p_bound; ++p) {
    for (int n = -n_bound; n <= n_bound; ++n) {
      double rest = 0.0;
      if (basis.rank >= 2) rest += n * basis.value[1];
      if (basis.rank >= 3) rest += p * basis.value[2];
      const double m_real = std::round((line.frequency - rest) / basis.value[0]);
      if (!(std::abs(m_real) <= bound)) continue;
      const Label candidate{static_cast<int>(m_real), n, p};
      const double error = std::abs(line.frequency - LatticeValue(basis, candidate));
      const double ratio = error / LabelTolerance(line, basis, candidate, options);
      if (ratio <= 1.0 && ratio < best_ratio) {
        best_ratio = ratio;
        *label = candidate;
        found = true;
      }
    }
  }
  return found;
}

// True if some nonzero integer vector with entries bounded by the largest
// label bound annihilates the basis within tolerance.
bool RationallyDependent(const Basis& basis, const BaseSelectionOptions& options) {
  const int bound = std::max(options.max_order, options.max_harmonic);
  LineEstimate zero;  // the relation sum m_i b_i = 0 is a "line" at frequency 0
  for (int p = (basis.rank >= 3 ? -bound : 0); p <= (basis.rank >= 3 ? bound : 0); ++p) {
    for (int n = (basis.rank >= 2 ? -bound : 0); n <= (basis.rank >= 2 ? bound : 0); ++n) {
      if (n == 0 && p == 0) continue;
      double rest = 0.0;
      if (basis.rank >= 2) rest += n * basis.value[1];
      if (basis.rank >= 3) rest += p * basis.value[2];
      const double m_real = std::round(-rest / basis.value[0]);
      if (!(std::abs(m_real) <= bound)) continue;
      const Label relation{static_cast<int>(m_real), n, p};
      if (std::abs(LatticeValue(basis, relation)) <=
          LabelTolerance(zero, basis, relation, options)) {
        return true;
      }
    }
  }
  return false;
}

Basis Transform(const Basis& basis, const IntMatrix& u) {
  Basis result = basis;
  for (int i = 0; i < basis.rank; ++i) {
    double value = 0.0, variance = 0.0;
    for (int j = 0; j < basis.rank; ++j) {
      value += u[i][j] * basis.value[j];
      variance += (u[i][j] * basis.sigma[j]) * (u[i][j] * basis.sigma[j]);
    }
    result.value[i] = value;
    result.sigma[i] = std::sqrt(variance);
  }
  return result;
}

// Labels all lines against `basis` (searching up to three times the label
// bound, so that labels in the unimodular equivalents can still be found),
// then keeps the best-scoring equivalent basis whose labels stay within the
// bound.
Evaluated EvaluateCandidate(const std::vector<LineEstimate>& lines, const Basis& basis,
                            const std::vector<Unimodular>& transforms,
                            const BaseSelectionOptions& options, double energy_tolerance) {
  const int count = static_cast<int>(lines.size());
  const int bound = LabelBound(basis.rank, options);
  const int search_bound = basis.rank > 1 ? 3 * bound : bound;
  std::vector<Label> raw(count);
  std::vector<char> raw_ok(count, 0);
  for (int k = 0; k < count; ++k) {
    raw_ok[k] = NearestLabel(lines[k], basis, search_bound, options, &raw[k]);
  }
  Evaluated best;
  for (const Unimodular& t : transforms) {
    const Basis candidate = Transform(basis, t.u);
    bool canonical = true;
    for (int i = basis.num_known; i < basis.rank && canonical; ++i) {
      if (!(candidate.value[i] > 0.0)) canonical = false;
      if (i > basis.num_known && !(candidate.value[i] > candidate.value[i - 1])) canonical = false;
    }
    if (!canonical) continue;
    Evaluated e;
    e.valid = true;
    e.basis = candidate;
    e.labels.assign(count, Label{0, 0, 0});
    e.explained.assign(count, 0);
    for (int k = 0; k < count; ++k) {
      bool ok = raw_ok[k];
      Label l{0, 0, 0};
      int norm = 0, squared_norm = 0, max_entry = 0;  // of l' below
      if (ok) {
        // l' = l U^-1
        for (int j = 0; j < basis.rank; ++j) {
          for (int i = 0; i < basis.rank; ++i) l[j] += raw[k][i] * t.inverse[i][j];
          norm += std::abs(l[j]);
          squared_norm += l[j] * l[j];
          max_entry = std::max(max_entry, std::abs(l[j]));
        }
        ok = max_entry <= bound;
      }
      if (ok) {
        e.labels[k] = l;
        e.explained[k] = 1;
        e.score.weighted_norm += std::sqrt(2.0 * lines[k].energy) * squared_norm;
        e.score.max_entry = std::max(e.score.max_entry, max_entry);
        if (norm == 1) {
          ++e.score.bases_as_lines;
          e.score.base_line_energy += lines[k].energy;
        }
      } else {
        e.score.unexplained_energy += lines[k].energy;
        ++e.score.num_unexplained;
      }
    }
    e.score.decay_misfit = DecayMisfit(lines, e.labels, e.explained, basis.rank);
    if (!best.valid || Better(e.score, best.score, energy_tolerance)) best = std::move(e);
  }
  return best;
}

// Calls visit(subset) for every subset of {0 .. n-1} of the given size.
template <typename Visitor>
void ForEachSubset(int n, int size, Visitor&& visit) {
  std::vector<int> subset(size);
  std::iota(subset.begin(), subset.end(), 0);
  if (size > n) return;
  while (true) {
    visit(subset);
    int i = size - 1;
    while (i >= 0 && subset[i] == n - size + i) --i;
    if (i < 0) return;
    ++subset[i];
    for (int j = i + 1; j < size; ++j) subset[j] = subset[j - 1] + 1;
  }
}

}  // namespace

bool SelectBases(const std::vector<LineEstimate>& lines, const BaseSelectionOptions& options,
                 BaseSelection* selection) {
  *selection = BaseSelection();
  const int count = static_cast<int>(lines.size());
  const int num_known = static_cast<int>(options.known_frequencies.size());
  auto fail = [selection](const std::string& message) {
    selection->message = message;
    return false;
  };
  if (options.max_bases < 1 || options.max_bases > kMaxRank) {
    return fail("max_bases must be 1, 2 or 3");
  }
  if (options.max_order < 1) return fail("max_order must be at least 1");
  if (num_known > options.max_bases) return fail("more known frequencies than max_bases");
  for (double f : options.known_frequencies) {
    if (!(std::isfinite(f) && f > 0.0)) return fail("known frequencies must be positive");
  }
  for (const LineEstimate& line : lines) {
    if (!(std::isfinite(line.frequency) && line.frequency > 0.0)) {
      return fail("line frequencies must be positive and finite");
    }
  }
  Basis known_basis;
  known_basis.rank = num_known;
  known_basis.num_known = num_known;
  for (int i = 0; i < num_known; ++i) known_basis.value[i] = options.known_frequencies[i];
  if (num_known >= 2 && RationallyDependent(known_basis, options)) {
    return fail("the known frequencies are rationally dependent");
  }

  double total_energy = 0.0;
  for (const LineEstimate& line : lines) total_energy += line.energy;
  const double energy_tolerance = options.energy_tolerance * total_energy;

  // Candidate pool: the strongest lines, then the common divisors of their
  // rationally related pairs (a periodic signal may lack its fundamental).
  std::vector<int> order(count);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&lines](int a, int b) { return lines[a].energy > lines[b].energy; });
  const int top = std::min(count, std::max(1, options.num_candidates));
  std::vector<LineEstimate> pool;
  auto add_to_pool = [&](const LineEstimate& candidate) {
    for (const LineEstimate& existing : pool) {
      const double tolerance =
          options.tolerance_factor * std::hypot(existing.uncertainty, candidate.uncertainty) +
          options.relative_tolerance_floor * std::max(existing.frequency, candidate.frequency);
      if (std::abs(existing.frequency - candidate.frequency) <= tolerance) return;
    }
    pool.push_back(candidate);
  };
  for (int i = 0; i < top; ++i) add_to_pool(lines[order[i]]);
  for (int a = 0; a < top; ++a) {
    for (int b = a + 1; b < top; ++b) {
      const LineEstimate& strong = lines[order[a]];
      const LineEstimate& other = lines[order[b]];
      // other / strong ~ p / q in lowest terms, q >= 2: gcd = strong / q.
      for (int q = 2; q <= options.max_order; ++q) {
        const double p_real = std::round(other.frequency / strong.frequency * q);
        if (p_real < 1.0 || p_real > LabelBound(1, options)) continue;
        const int p = static_cast<int>(p_real);
        if (std::gcd(p, q) != 1) continue;
        const double mismatch = std::abs(q * other.frequency - p * strong.frequency);
        const double tolerance =
            options.tolerance_factor * std::hypot(q * other.uncertainty, p * strong.uncertainty) +
            options.relative_tolerance_floor * q * other.frequency;
        if (mismatch <= tolerance) {
          add_to_pool({strong.frequency / q, strong.uncertainty / q, 0.0});
          break;
        }
      }
    }
  }

  // Best candidate of every admissible rank.
  const int min_rank = std::max(1, num_known);
  std::vector<Evaluated> best_by_rank(kMaxRank + 1);
  for (int rank = min_rank; rank <= options.max_bases; ++rank) {
    const std::vector<Unimodular> transforms = UnimodularTransforms(rank, num_known);
    const int free = rank - num_known;
    // Triples are costly to canonicalise; fewer of the strongest suffice.
    const int pool_size = std::min<int>(pool.size(), rank == 3 ? 8 : 1 << 20);
    ForEachSubset(pool_size, free, [&](const std::vector<int>& subset) {
      Basis basis = known_basis;
      basis.rank = rank;
      for (int j = 0; j < free; ++j) {
        basis.value[num_known + j] = pool[subset[j]].frequency;
        basis.sigma[num_known + j] = pool[subset[j]].uncertainty;
      }
      if (rank >= 2 && RationallyDependent(basis, options)) return;
      ++selection->num_candidate_bases_tried;
      Evaluated e = EvaluateCandidate(lines, basis, transforms, options, energy_tolerance);
      if (e.valid && (!best_by_rank[rank].valid ||
                      Better(e.score, best_by_rank[rank].score, energy_tolerance))) {
        best_by_rank[rank] = std::move(e);
      }
    });
  }
  int chosen = -1;
  for (int rank = min_rank; rank <= options.max_bases; ++rank) {
    if (!best_by_rank[rank].valid) continue;
    if (chosen < 0) {
      chosen = rank;
      continue;
    }
    const Score& current = best_by_rank[chosen].score;
    const Score& next = best_by_rank[rank].score;
    const bool more_energy =
        next.unexplained_energy < current.unexplained_energy - energy_tolerance;
    const bool more_lines = current.num_unexplained - next.num_unexplained >= 2 * (rank - chosen);
    if (more_energy || more_lines) chosen = rank;
  }

  if (chosen < 0) {
    // No line to build a basis from: only the known frequencies, if any.
    for (int i = 0; i < num_known; ++i) {
      selection->bases.push_back({options.known_frequencies[i], 0.0, true, -1});
    }
    selection->labels.assign(count, {});
    selection->lattice_residuals.assign(count, std::numeric_limits<double>::quiet_NaN());
    selection->message = count == 0 ? "no lines to explain" : "no admissible basis";
    return true;
  }

  Evaluated& best = best_by_rank[chosen];
  Basis basis = best.basis;
  const int rank = basis.rank;
  // Weighted least squares for the bases that are not known.
  if (options.refine_bases && rank > num_known) {
    const int free = rank - num_known;
    Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(free, free);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(free);
    for (int k = 0; k < count; ++k) {
      if (!best.explained[k]) continue;
      const double sigma = std::max(lines[k].uncertainty,
                                    std::numeric_limits<double>::epsilon() * lines[k].frequency);
      const double weight = 1.0 / (sigma * sigma);
      double target = lines[k].frequency;
      for (int i = 0; i < num_known; ++i) target -= best.labels[k][i] * basis.value[i];
      Eigen::VectorXd row(free);
      for (int j = 0; j < free; ++j) row(j) = best.labels[k][num_known + j];
      normal.noalias() += weight * row * row.transpose();
      rhs.noalias() += weight * target * row;
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(normal);
    const Eigen::VectorXd refined = ldlt.solve(rhs);
    const Eigen::MatrixXd covariance = ldlt.solve(Eigen::MatrixXd::Identity(free, free));
    const bool full_rank = ldlt.info() == Eigen::Success && ldlt.isPositive() &&
                           (ldlt.vectorD().array() > 0.0).all() && refined.allFinite();
    if (full_rank) {
      for (int j = 0; j < free; ++j) {
        basis.value[num_known + j] = refined(j);
        basis.sigma[num_known + j] = std::sqrt(std::max(0.0, covariance(j, j)));
      }
    }
  }

  selection->labels.assign(count, {});
  selection->lattice_residuals.assign(count, std::numeric_limits<double>::quiet_NaN());
  double explained_energy = 0.0;
  for (int i = 0; i < rank; ++i) {
    selection->bases.push_back({basis.value[i], basis.sigma[i], i < num_known, -1});
  }
  for (int k = 0; k < count; ++k) {
    if (!best.explained[k]) continue;
    const Label& l = best.labels[k];
    selection->labels[k].assign(l.begin(), l.begin() + rank);
    selection->lattice_residuals[k] = lines[k].frequency - LatticeValue(basis, l);
    ++selection->num_explained;
    explained_energy += lines[k].energy;
    int norm = 0, unit = -1;
    for (int i = 0; i < rank; ++i) {
      norm += std::abs(l[i]);
      if (l[i] == 1) unit = i;
    }
    if (norm == 1 && unit >= 0) {
      int& line = selection->bases[unit].line;
      if (line < 0 || lines[k].energy > lines[line].energy) line = k;
    }
  }
  selection->explained_energy_fraction = total_energy > 0.0 ? explained_energy / total_energy : 1.0;
  std::ostringstream os;
  os << rank << (rank == 1 ? " base explains " : " bases explain ") << selection->num_explained
     << " of " << count << " lines (" << 100.0 * selection->explained_energy_fraction
     << "% of the energy)";
  selection->message = os.str();
  return true;
}

}  // namespace rmhb::frequency_id
