#include "rmhb/spectral_transform.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace rmhb {
namespace {

// FFTW's planner is not thread-safe; execution is.
std::mutex& PlannerMutex() {
  static std::mutex m;
  return m;
}

inline int Mod(long a, int m) {
  long r = a % m;
  return static_cast<int>(r < 0 ? r + m : r);
}

// One (forward, backward) plan pair per grid for the whole process. Plans
// are made on fftw_malloc'd arrays and executed with the new-array interface
// on other fftw_malloc'd arrays (same alignment), which FFTW allows and
// which is thread-safe. They live as long as the process.
std::pair<fftw_plan, fftw_plan> CachedPlans(const std::vector<int>& grid, long total, long half_total) {
  static auto* cache = new std::map<std::vector<int>, std::pair<fftw_plan, fftw_plan>>;
  std::lock_guard<std::mutex> lock(PlannerMutex());
  auto it = cache->find(grid);
  if (it != cache->end()) return it->second;
  double* real = fftw_alloc_real(total);
  fftw_complex* spectrum = fftw_alloc_complex(half_total);
  const int dims = static_cast<int>(grid.size());
  fftw_plan forward = fftw_plan_dft_r2c(dims, grid.data(), real, spectrum, FFTW_ESTIMATE);
  fftw_plan backward = fftw_plan_dft_c2r(dims, grid.data(), spectrum, real, FFTW_ESTIMATE);
  fftw_free(real);
  fftw_free(spectrum);
  if (!forward || !backward) throw std::runtime_error("SpectralTransform: FFTW planning failed");
  return cache->emplace(grid, std::make_pair(forward, backward)).first->second;
}

// The dense backend's tables, shared by every transform of the same grid in
// the process (a handful, most recent first): continuation, Monte Carlo,
// order continuation and repeated library solves build the same tables over
// and over, and building them (O(M K) cos/sin lookups, O(M^2) for the
// spectrum) costs more than a Newton iteration of a small problem.
template <typename Key, typename Tables>
class TableCache {
 public:
  template <typename Make>
  std::shared_ptr<const Tables> Get(const Key& key, Make make) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& [k, tables] : entries_)
      if (k == key) return tables;
    auto tables = std::make_shared<const Tables>(make());
    entries_.emplace_front(key, tables);
    if (entries_.size() > 16) entries_.pop_back();
    return tables;
  }

 private:
  std::mutex mutex_;
  std::deque<std::pair<Key, std::shared_ptr<const Tables>>> entries_;
};

// cos and sin of 2 pi j / M, j < M: every phase is reduced mod M exactly.
void UnitCircle(long M, Eigen::VectorXd* c, Eigen::VectorXd* s) {
  c->resize(M);
  s->resize(M);
  for (long j = 0; j < M; ++j) {
    const double a = 2.0 * M_PI * double(j) / double(M);
    (*c)(j) = std::cos(a);
    (*s)(j) = std::sin(a);
  }
}

}  // namespace

// The dense backend on the half grid t = 0 .. M/2 (H = M/2 + 1 samples):
// cos(g t) is even and sin(g t) odd about t = 0 (and t = M/2), so E's rows
// past M/2 repeat the first ones, the sin columns negated, and a sum over the
// grid against them is a sum over the half grid against the samples' even
// and odd parts (Fold). Half the tables' memory, whose first-touch page
// faults were a fifth of a first solve in a fresh process, and half the
// multiply-adds of every synthesis, projection and analysis (issue 14).
struct SpectralTransform::DenseTables {
  Eigen::MatrixXd cos;  // H x K: cos(g_k t); column 0 the constant 1
  Eigen::MatrixXd sin;  // H x K: sin(g_k t); column 0 zero, exact zeros at t = 0 and M/2
};
// The half spectrum's indices that no harmonic of the basis reaches (the
// products' harmonics beyond it) and their real and imaginary rows on the
// half grid, scaled by 1/M (the imaginary negated); the basis's own come
// from DenseTables (Analyze).
struct SpectralTransform::SpectrumTables {
  std::vector<long> rows;
  Eigen::MatrixXd cos, sin;  // rows x H
};

SpectralTransform::SpectralTransform(const HarmonicBasis& basis, const Sampling& sampling,
                                     Backend backend)
    : basis_(basis), sampling_(sampling), dims_(static_cast<int>(sampling.grid.size())) {
  if (dims_ < 1 || dims_ > 3) throw std::invalid_argument("SpectralTransform: 1 to 3 grid angles");
  if (static_cast<int>(sampling.embedding.size()) != dims_)
    throw std::invalid_argument("SpectralTransform: embedding rows must match grid angles");
  for (const auto& row : sampling.embedding)
    if (static_cast<int>(row.size()) != basis.num_bases())
      throw std::invalid_argument("SpectralTransform: embedding columns must match base count");
  total_ = sampling.total();
  if (total_ > 200'000'000L)
    throw std::invalid_argument("SpectralTransform: " + std::to_string(total_) +
                                " samples requested; refusing (memory)");
  half_total_ = total_ / sampling.grid.back() * (sampling.grid.back() / 2 + 1);

  // Each harmonic must own a distinct grid frequency (up to sign), else the
  // grid cannot tell its cos and sin apart from another's.
  // Keys: the flat grid index of g or of -g, whichever is smaller; two
  // harmonics collide exactly when their keys are equal.
  std::vector<long> keys(basis.size());
  grid_index_.reserve(static_cast<size_t>(basis.size()) * dims_);
  for (int k = 0; k < basis.size(); ++k) {
    long g = 0, neg = 0;
    for (int d = 0; d < dims_; ++d) {
      long v = 0;
      for (int i = 0; i < basis.num_bases(); ++i) v += long(sampling.embedding[d][i]) * basis.harmonic(k)[i];
      grid_index_.push_back(static_cast<int>(v));
      g = g * sampling.grid[d] + Mod(v, sampling.grid[d]);
      neg = neg * sampling.grid[d] + Mod(-v, sampling.grid[d]);
    }
    if (k > 0 && g == neg)
      throw std::invalid_argument("SpectralTransform: harmonic " + std::to_string(k) +
                                  " sits at the Nyquist frequency of the grid; use more samples");
    keys[k] = std::min(g, neg);
  }
  std::sort(keys.begin(), keys.end());
  if (std::adjacent_find(keys.begin(), keys.end()) != keys.end())
    throw std::invalid_argument("SpectralTransform: two harmonics share a grid frequency; "
                                "the sampling is too coarse for the basis");

  if (!sampling.half_step.empty()) SetUpShift(sampling.half_step);
  analysed_.resize(half_total_);
  if (backend == Backend::kDense && dims_ != 1)
    throw std::invalid_argument("SpectralTransform: the dense backend needs a grid of one angle");
  dense_ = backend == Backend::kDense ||
           (backend == Backend::kAuto && dims_ == 1 && total_ <= kMaxDenseSamples);
  if (dense_) {
    SetUpDense();
    return;
  }
  real_ = fftw_alloc_real(total_);
  spectrum_ = reinterpret_cast<std::complex<double>*>(fftw_alloc_complex(half_total_));
  const auto plans = CachedPlans(sampling.grid, total_, half_total_);
  forward_ = plans.first;
  backward_ = plans.second;
}

SpectralTransform::~SpectralTransform() {
  fftw_free(real_);
  fftw_free(spectrum_);
}

void SpectralTransform::SetUpDense() {
  static auto* cache = new TableCache<std::pair<long, std::vector<int>>, DenseTables>;
  const long M = total_, H = M / 2 + 1;
  const int K = basis_.size();
  dense_tables_ = cache->Get({M, grid_index_}, [&] {
    Eigen::VectorXd c, s;
    UnitCircle(M, &c, &s);
    DenseTables tables;
    tables.cos.resize(H, K);
    tables.sin.resize(H, K);
    tables.cos.col(0).setOnes();
    tables.sin.col(0).setZero();
    // The phase index g t mod M advanced by g per sample: a 64-bit division
    // per entry was most of a first solve's table time (issue 14).
    for (int k = 1; k < K; ++k) {
      const long g = Mod(grid_index_[k], static_cast<int>(M));
      for (long t = 0, j = 0; t < H; ++t, j = j + g < M ? j + g : j + g - M) {
        tables.cos(t, k) = c(j);
        tables.sin(t, k) = 2 * t == M ? 0.0 : s(j);  // sin(g pi) = 0, not sin's round-off
      }
    }
    return tables;
  });
  even_.resize(H);
  odd_.resize(H);
  cos_part_.resize(K);
  sin_part_.resize(K);
}

// The samples' even and odd parts about t = 0 on the half grid: the sum of
// p_t cos(g t) over the grid is that of even_t cos(g t) over the half grid,
// and the same for sin with odd_ (t = 0 and t = M/2 are their own mirrors).
void SpectralTransform::Fold(const double* p) {
  const long M = total_;
  even_(0) = p[0];
  odd_(0) = 0;
  for (long t = 1; 2 * t < M; ++t) {
    even_(t) = p[t] + p[M - t];
    odd_(t) = p[t] - p[M - t];
  }
  if (M % 2 == 0) even_(M / 2) = p[M / 2], odd_(M / 2) = 0;
}

// Samples whose cos part on the half grid is even_ and sin part odd_ (zero
// at t = 0 and t = M/2, where the sin tables are).
void SpectralTransform::Unfold(double* p) const {
  const long M = total_;
  p[0] = even_(0);
  for (long t = 1; 2 * t < M; ++t) {
    p[t] = even_(t) + odd_(t);
    p[M - t] = even_(t) - odd_(t);
  }
  if (M % 2 == 0) p[M / 2] = even_(M / 2);
}

// cos_part_ = (cos table)' even_, sin_part_ = (sin table)' odd_: every
// harmonic's sums over the grid (Fold first).
void SpectralTransform::DenseSums() {
  cos_part_.noalias() = dense_tables_->cos.transpose() * even_;
  sin_part_.noalias() = dense_tables_->sin.transpose() * odd_;
}

void SpectralTransform::SetUpDenseSpectrum() {
  static auto* cache = new TableCache<std::pair<long, std::vector<int>>, SpectrumTables>;
  const long M = total_, half = half_total_;
  spectrum_tables_ = cache->Get({M, grid_index_}, [&] {
    std::vector<char> reached(half, 0);
    for (int g : grid_index_) {
      const long r = Mod(g, static_cast<int>(M));
      reached[r <= M / 2 ? r : M - r] = 1;
    }
    SpectrumTables tables;
    for (long k = 0; k < half; ++k)
      if (!reached[k]) tables.rows.push_back(k);
    const long n = static_cast<long>(tables.rows.size());
    Eigen::VectorXd c, s;
    UnitCircle(M, &c, &s);
    const long H = M / 2 + 1;
    tables.cos.resize(n, H);
    tables.sin.resize(n, H);
    for (long i = 0; i < n; ++i) {
      const long g = tables.rows[i];  // in [0, M / 2]
      for (long t = 0, j = 0; t < H; ++t, j = j + g < M ? j + g : j + g - M) {
        tables.cos(i, t) = c(j) / double(M);
        tables.sin(i, t) = 2 * t == M ? 0.0 : -s(j) / double(M);
      }
    }
    return tables;
  });
  half_re_.resize(spectrum_tables_->cos.rows());
  half_im_.resize(spectrum_tables_->cos.rows());
}

long SpectralTransform::HalfIndex(const int* r) const {
  long idx = 0;
  for (int d = 0; d < dims_ - 1; ++d) idx = idx * sampling_.grid[d] + r[d];
  return idx * (sampling_.grid.back() / 2 + 1) + r[dims_ - 1];
}

std::complex<double> SpectralTransform::SpectrumAt(const int* g) const {
  if (dims_ == 1) {
    // One angle: one reduction, not two (a Jacobian block asks for dozens).
    const int M = sampling_.grid[0], r = Mod(g[0], M);
    return r <= M / 2 ? analysed_[r] : std::conj(analysed_[r == 0 ? 0 : M - r]);
  }
  int r[3], n[3];
  for (int d = 0; d < dims_; ++d) {
    r[d] = Mod(g[d], sampling_.grid[d]);
    n[d] = Mod(-long(g[d]), sampling_.grid[d]);
  }
  const int last = sampling_.grid.back();
  if (r[dims_ - 1] <= last / 2) return analysed_[HalfIndex(r)];
  return std::conj(analysed_[HalfIndex(n)]);
}

void SpectralTransform::SetUpShift(const std::vector<int>& half_step) {
  if (static_cast<int>(half_step.size()) != dims_)
    throw std::invalid_argument("SpectralTransform: half_step needs one flag per grid angle");
  for (int h : half_step)
    if (h != 0 && h != 1) throw std::invalid_argument("SpectralTransform: half_step flags are 0 or 1");
  if (std::find(half_step.begin(), half_step.end(), 1) == half_step.end()) return;
  half_step_ = half_step;
  const int K = basis_.size();
  advance_cos_.resize(K);
  advance_sin_.resize(K);
  for (int k = 0; k < K; ++k) {
    // Half a step along angle d advances harmonic k by g_d pi / M_d, in
    // turns g_d mod 2 M_d over 2 M_d (reduced exactly, as Phase).
    double turns = 0;
    for (int d = 0; d < dims_; ++d) {
      const int twice = 2 * sampling_.grid[d];
      if (half_step[d]) turns += double(Mod(grid_index_[k * dims_ + d], twice)) / twice;
    }
    const double a = 2.0 * M_PI * (turns - std::floor(turns));
    advance_cos_[k] = std::cos(a);
    advance_sin_[k] = std::sin(a);
  }
  turned_.setZero(num_coefficients());
  projected_.setZero(num_coefficients());
}

// x on the shifted grid is the grid's transform of x turned by each
// harmonic's advance p: a cos(k theta + p) + b sin(k theta + p) =
// (a cos p + b sin p) cos k theta + (b cos p - a sin p) sin k theta.
// Entries outside `some` (when given) count as zero.
const double* SpectralTransform::Advance(const double* x, const std::vector<int>* some) {
  if (half_step_.empty()) return x;
  if (some) {
    turned_.setZero();
    for (int c : *some) turned_(c) = x[c];
  } else {
    turned_ = Eigen::Map<const Eigen::VectorXd>(x, num_coefficients());
  }
  for (int k = 1; k < basis_.size(); ++k) {
    const double a = turned_(2 * k - 1), b = turned_(2 * k), c = advance_cos_[k], s = advance_sin_[k];
    turned_(2 * k - 1) = a * c + b * s;
    turned_(2 * k) = b * c - a * s;
  }
  return turned_.data();
}

// The inverse of Advance on a projection: the grid's coefficients of the
// shifted samples, turned back to the harmonics of the unshifted angle.
void SpectralTransform::TurnBack(double* x) const {
  for (int k = 1; k < basis_.size(); ++k) {
    const double a = x[2 * k - 1], b = x[2 * k], c = advance_cos_[k], s = advance_sin_[k];
    x[2 * k - 1] = a * c - b * s;
    x[2 * k] = a * s + b * c;
  }
}

// `some` with the cos and sin of each of its harmonics: a turn mixes them.
std::vector<int> SpectralTransform::BothOfEachHarmonic(const std::vector<int>& some) const {
  std::vector<int> both;
  for (int c : some) {
    if (c == 0) {
      both.push_back(0);
      continue;
    }
    const int k = (c + 1) / 2;
    both.push_back(2 * k - 1);
    both.push_back(2 * k);
  }
  std::sort(both.begin(), both.end());
  both.erase(std::unique(both.begin(), both.end()), both.end());
  return both;
}

void SpectralTransform::Synthesize(const double* x, double* samples) {
  SynthesizeOnGrid(Advance(x, nullptr), samples);
}

void SpectralTransform::SynthesizeSome(const double* x, const std::vector<int>& some, double* samples) {
  if (half_step_.empty()) return SynthesizeSomeOnGrid(x, some, samples);
  SynthesizeSomeOnGrid(Advance(x, &some), BothOfEachHarmonic(some), samples);
}

void SpectralTransform::Project(const double* samples, double* x) {
  ProjectOnGrid(samples, x);
  if (!half_step_.empty()) TurnBack(x);
}

void SpectralTransform::ProjectSome(const double* samples, const std::vector<int>& some, double* x) {
  if (half_step_.empty()) return ProjectSomeOnGrid(samples, some, x);
  ProjectSomeOnGrid(samples, BothOfEachHarmonic(some), projected_.data());
  TurnBack(projected_.data());
  for (int c : some) x[c] = projected_(c);
}

void SpectralTransform::SynthesizeOnGrid(const double* x, double* samples) {
  if (dense_) {
    cos_part_(0) = x[0];
    sin_part_(0) = 0;
    for (int k = 1; k < basis_.size(); ++k) cos_part_(k) = x[2 * k - 1], sin_part_(k) = x[2 * k];
    even_.noalias() = dense_tables_->cos * cos_part_;
    odd_.noalias() = dense_tables_->sin * sin_part_;
    Unfold(samples);
    return;
  }
  std::memset(static_cast<void*>(spectrum_), 0, sizeof(std::complex<double>) * half_total_);
  const int last = sampling_.grid.back();
  spectrum_[0] += x[0];
  for (int k = 1; k < basis_.size(); ++k) {
    const std::complex<double> c(0.5 * x[2 * k - 1], -0.5 * x[2 * k]);
    int r[3], n[3];
    for (int d = 0; d < dims_; ++d) {
      r[d] = Mod(grid_index_[k * dims_ + d], sampling_.grid[d]);
      n[d] = Mod(-long(grid_index_[k * dims_ + d]), sampling_.grid[d]);
    }
    if (r[dims_ - 1] <= last / 2) spectrum_[HalfIndex(r)] += c;
    if (n[dims_ - 1] <= last / 2) spectrum_[HalfIndex(n)] += std::conj(c);
  }
  fftw_execute_dft_c2r(static_cast<fftw_plan>(backward_), reinterpret_cast<fftw_complex*>(spectrum_), real_);
  std::memcpy(samples, real_, sizeof(double) * total_);
}

void SpectralTransform::SynthesizeSomeOnGrid(const double* x, const std::vector<int>& some, double* samples) {
  if (!dense_) return SynthesizeOnGrid(x, samples);
  const long H = even_.size();
  double* cos_sum = even_.data();
  double* sin_sum = odd_.data();
  std::fill(cos_sum, cos_sum + H, 0.0);
  std::fill(sin_sum, sin_sum + H, 0.0);
  const DenseTables& E = *dense_tables_;
  // Four columns per pass over a sum: a quarter of the loads and stores of
  // the sum that one axpy per column would take.
  struct Batch {
    const double* column[4];
    double a[4];
    int n = 0;
  } cos_batch, sin_batch;
  auto flush = [H](Batch* b, double* sum) {
    if (b->n == 4) {
      const double *c0 = b->column[0], *c1 = b->column[1], *c2 = b->column[2], *c3 = b->column[3];
      const double a0 = b->a[0], a1 = b->a[1], a2 = b->a[2], a3 = b->a[3];
      for (long t = 0; t < H; ++t) sum[t] += a0 * c0[t] + a1 * c1[t] + a2 * c2[t] + a3 * c3[t];
    } else {
      for (int i = 0; i < b->n; ++i)
        for (long t = 0; t < H; ++t) sum[t] += b->a[i] * b->column[i][t];
    }
    b->n = 0;
  };
  for (int c : some) {
    const bool is_sin = c > 0 && c % 2 == 0;
    Batch& b = is_sin ? sin_batch : cos_batch;
    b.column[b.n] = is_sin ? E.sin.col(c / 2).data() : E.cos.col((c + 1) / 2).data();
    b.a[b.n++] = x[c];
    if (b.n == 4) flush(&b, is_sin ? sin_sum : cos_sum);
  }
  flush(&cos_batch, cos_sum);
  flush(&sin_batch, sin_sum);
  Unfold(samples);
}

void SpectralTransform::ProjectSomeOnGrid(const double* samples, const std::vector<int>& some, double* x) {
  if (!dense_) return ProjectOnGrid(samples, x);
  // Row c of E* is column c of E times 2/M (1/M for the mean): a dot on the
  // half grid with the samples' even (cos) or odd (sin) part.
  Fold(samples);
  const DenseTables& E = *dense_tables_;
  const double scale = 2.0 / double(total_);
  for (int c : some)
    x[c] = c == 0 ? 0.5 * scale * even_.sum()
           : c % 2 ? scale * E.cos.col((c + 1) / 2).dot(even_)
                   : scale * E.sin.col(c / 2).dot(odd_);
}

void SpectralTransform::ForwardFftw(const double* samples) {
  std::memcpy(real_, samples, sizeof(double) * total_);
  fftw_execute_dft_r2c(static_cast<fftw_plan>(forward_), real_, reinterpret_cast<fftw_complex*>(spectrum_));
}

void SpectralTransform::ProjectOnGrid(const double* samples, double* x) {
  if (dense_) {
    Fold(samples);
    DenseSums();
    const double scale = 2.0 / double(total_);
    x[0] = 0.5 * scale * cos_part_(0);
    for (int k = 1; k < basis_.size(); ++k) x[2 * k - 1] = scale * cos_part_(k), x[2 * k] = scale * sin_part_(k);
    return;
  }
  ForwardFftw(samples);
  const double inv = 1.0 / double(total_);
  const int last = sampling_.grid.back();
  x[0] = spectrum_[0].real() * inv;
  for (int k = 1; k < basis_.size(); ++k) {
    int r[3], n[3];
    for (int d = 0; d < dims_; ++d) {
      r[d] = Mod(grid_index_[k * dims_ + d], sampling_.grid[d]);
      n[d] = Mod(-long(grid_index_[k * dims_ + d]), sampling_.grid[d]);
    }
    const std::complex<double> c = r[dims_ - 1] <= last / 2 ? spectrum_[HalfIndex(r)]
                                                             : std::conj(spectrum_[HalfIndex(n)]);
    x[2 * k - 1] = 2.0 * c.real() * inv;
    x[2 * k] = -2.0 * c.imag() * inv;
  }
}

void SpectralTransform::Analyze(const double* samples) {
  if (!half_step_.empty())
    throw std::logic_error("SpectralTransform: a shifted grid serves residual evaluations, not Jacobians");
  if (dense_) {
    if (!spectrum_tables_) SetUpDenseSpectrum();
    // The basis's harmonics: P[r] = (cos . p - i sin . p) / M at their grid
    // index r (conjugated past M / 2).
    Fold(samples);
    DenseSums();
    const double inv = 1.0 / double(total_);
    const int M = static_cast<int>(total_);
    analysed_[0] = cos_part_(0) * inv;
    for (int k = 1; k < basis_.size(); ++k) {
      const int r = Mod(grid_index_[k], M);
      const double re = cos_part_(k) * inv, im = sin_part_(k) * inv;
      if (r <= M / 2)
        analysed_[r] = {re, -im};
      else
        analysed_[M - r] = {re, im};
    }
    const SpectrumTables& beyond = *spectrum_tables_;
    half_re_.noalias() = beyond.cos * even_;
    half_im_.noalias() = beyond.sin * odd_;
    for (size_t i = 0; i < beyond.rows.size(); ++i) analysed_[beyond.rows[i]] = {half_re_(i), half_im_(i)};
    return;
  }
  ForwardFftw(samples);
  const double inv = 1.0 / double(total_);
  for (long i = 0; i < half_total_; ++i) analysed_[i] = spectrum_[i] * inv;
}

void SpectralTransform::GatherLineSpectrum(int first, int last) const {
  // One angle: the spectrum at every grid index k +- l can reach, gathered
  // once (the general lookup reduces indices modulo the grid per entry,
  // which was 60 % of a Jacobian at N = 55). Only the indices harmonics
  // [first, last) reach: differences within +-(max - min) of their grid
  // indices, sums within 2 min .. 2 max (a diagonal block of a high harmonic
  // needs a handful, not the whole line: the coarsened Jacobians of
  // METHOD.md s.17 ask for thousands of them).
  int lowest = grid_index_[first], highest = grid_index_[first];
  for (int k = first; k < last; ++k) {
    lowest = std::min(lowest, grid_index_[k]);
    highest = std::max(highest, grid_index_[k]);
  }
  line_span_ = highest - lowest;
  line_low_ = 2 * lowest;
  line_spectrum_.resize(2 * line_span_ + 1);
  sum_spectrum_.resize(2 * line_span_ + 1);
  for (int g = -line_span_; g <= line_span_; ++g) line_spectrum_[g + line_span_] = SpectrumAt(&g);
  for (int g = line_low_; g <= line_low_ + 2 * line_span_; ++g) sum_spectrum_[g - line_low_] = SpectrumAt(&g);
}

// Inline: called once per entry pair of every Jacobian block.
inline SpectralTransform::ProductPair SpectralTransform::ProductAt(int k, int l) const {
  std::complex<double> pd, ps;
  if (dims_ == 1) {
    const int gk = grid_index_[k], gl = grid_index_[l];
    pd = line_spectrum_[gk - gl + line_span_];
    if (l > 0) ps = sum_spectrum_[gk + gl - line_low_];
  } else {
    int sum[3], diff[3];
    for (int d = 0; d < dims_; ++d) {
      sum[d] = grid_index_[k * dims_ + d] + grid_index_[l * dims_ + d];
      diff[d] = grid_index_[k * dims_ + d] - grid_index_[l * dims_ + d];
    }
    pd = SpectrumAt(diff);
    if (l > 0) ps = SpectrumAt(sum);
  }
  if (l == 0) return {pd, {}};
  // -i/2 (P[k-l] - P[k+l]) written out: no complex product's NaN checks.
  return {0.5 * (pd + ps), {0.5 * (pd.imag() - ps.imag()), -0.5 * (pd.real() - ps.real())}};
}

namespace {

// The entries of scale * E* diag(p) E (D) that harmonic l's columns give in
// harmonic k's rows, each handed to put(row coefficient, column coefficient,
// value): rows a_0 = Re c, a_k = 2 Re c, b_k = -2 Im c of the component c
// (c_cos, c_sin: SpectralTransform::ProductAt); columns l's cos and sin, or
// under D(rate) d/dt(a cos) = -rate a sin, d/dt(b sin) = rate b cos.
template <class Put>
inline void PutProduct(int k, int l, std::complex<double> c_cos, std::complex<double> c_sin, double scale,
                       const double* rate, Put&& put) {
  auto rows = [&](int column, std::complex<double> v, double w) {
    if (w == 0.0) return;
    if (k == 0) {
      put(0, column, w * v.real());
    } else {
      put(2 * k - 1, column, w * 2.0 * v.real());
      put(2 * k, column, w * -2.0 * v.imag());
    }
  };
  if (!rate) {
    rows(l == 0 ? 0 : 2 * l - 1, c_cos, scale);
    if (l > 0) rows(2 * l, c_sin, scale);
  } else if (l > 0) {
    rows(2 * l - 1, c_sin, -scale * rate[l]);
    rows(2 * l, c_cos, scale * rate[l]);
  }
}

}  // namespace

void SpectralTransform::AddMultiplicationMatrix(double scale, const double* rate,
                                                Eigen::Ref<Eigen::MatrixXd> out,
                                                const char* row_harmonics,
                                                const char* column_harmonics) const {
  AddMultiplicationBlock(scale, rate, 0, basis_.size(), out, row_harmonics, column_harmonics);
}

void SpectralTransform::AddMultiplicationBlock(double scale, const double* rate, int first,
                                               int last, Eigen::Ref<Eigen::MatrixXd> out,
                                               const char* row_harmonics,
                                               const char* column_harmonics) const {
  if (dims_ == 1) GatherLineSpectrum(first, last);
  // Coefficient positions in `out`: harmonic k's cos at 2k - 1 - offset.
  const int offset = first == 0 ? 0 : 2 * first - 1;
  auto put = [&](int row, int column, double value) { out(row - offset, column - offset) += value; };
  for (int l = first; l < last; ++l) {
    if (column_harmonics && !column_harmonics[l]) continue;
    for (int k = first; k < last; ++k)
      if (!row_harmonics || row_harmonics[k]) {
        const ProductPair c = ProductAt(k, l);
        PutProduct(k, l, c.cos, c.sin, scale, rate, put);
      }
  }
}

void SpectralTransform::AddConstantMultiplication(double value, const double* rate,
                                                  Eigen::Ref<Eigen::MatrixXd> out) const {
  if (!rate) {
    out.diagonal().array() += value;
    return;
  }
  // d/dt(a cos) = -rate a sin; d/dt(b sin) = rate b cos (AddMultiplicationBlock).
  for (int k = 1; k < basis_.size(); ++k) {
    out(2 * k - 1, 2 * k) += value * rate[k];
    out(2 * k, 2 * k - 1) -= value * rate[k];
  }
}

void SpectralTransform::AddMultiplicationTo(const double* rate, const Targets& targets,
                                            Eigen::Ref<Eigen::MatrixXd> out) const {
  if (dims_ != 1) throw std::logic_error("SpectralTransform::AddMultiplicationTo: one grid angle only");
  const int K = basis_.size();
  GatherLineSpectrum(0, K);
  // The row harmonics some target keeps: the inner loop runs over them only.
  const int* rows = targets.rows;
  active_rows_.clear();
  for (int k = 0; k < K; ++k)
    if (rows[k == 0 ? 0 : 2 * k - 1] >= 0 || (k > 0 && rows[2 * k] >= 0)) active_rows_.push_back(k);
  auto put = [&](int row, int column, double value) {
    if (rows[row] >= 0 && targets.columns[column] >= 0) out(rows[row], targets.columns[column]) += value;
  };
  for (int l = 0; l < K; ++l) {
    const bool use_cos = targets.columns[l == 0 ? 0 : 2 * l - 1] >= 0, use_sin = l > 0 && targets.columns[2 * l] >= 0;
    if (!use_cos && !use_sin) continue;
    if (rate && (l == 0 || rate[l] == 0.0)) continue;  // D(rate) has no such column
    for (int k : active_rows_) {
      const ProductPair c = ProductAt(k, l);
      PutProduct(k, l, c.cos, c.sin, 1.0, rate, put);
    }
  }
}

void SpectralTransform::AddConstantMultiplicationTo(double value, const double* rate, const Targets& targets,
                                                    Eigen::Ref<Eigen::MatrixXd> out) const {
  auto put = [&](int row, int column, double entry) {
    if (targets.rows[row] >= 0 && targets.columns[column] >= 0) out(targets.rows[row], targets.columns[column]) += entry;
  };
  if (!rate) {
    for (int c = 0; c < num_coefficients(); ++c) put(c, c, value);
    return;
  }
  for (int k = 1; k < basis_.size(); ++k) {
    put(2 * k - 1, 2 * k, value * rate[k]);
    put(2 * k, 2 * k - 1, -(value * rate[k]));
  }
}

long SpectralTransform::GridRate(const std::vector<int>& h, int d) const {
  long g = 0;
  for (int i = 0; i < basis_.num_bases() && i < static_cast<int>(h.size()); ++i)
    g += long(sampling_.embedding[d][i]) * h[i];
  return g;
}

double SpectralTransform::Phase(const std::vector<int>& h, long sample) const {
  // Decompose the flat sample index into grid coordinates (last fastest).
  double phase = 0.0;
  long s = sample;
  for (int d = dims_ - 1; d >= 0; --d) {
    const int m = sampling_.grid[d];
    const long coord = s % m;
    s /= m;
    const long g = GridRate(h, d);
    // Half a step on: (2 coord + 1) / (2 m) of a turn.
    phase += half_step_.empty() || !half_step_[d] ? double(Mod(g * coord, m)) / m
                                                  : double(Mod(g * (2 * coord + 1), 2 * m)) / (2.0 * m);
  }
  return 2.0 * M_PI * (phase - std::floor(phase));
}

void SpectralTransform::Phases(const std::vector<int>& h, double* phases) const {
  if (dims_ != 1 || !half_step_.empty()) {
    for (long s = 0; s < total_; ++s) phases[s] = Phase(h, s);
    return;
  }
  // One angle: the index g s mod M advanced by g per sample, the same value
  // as Phase's (a residual samples every time function at every sample: a
  // reduction per sample was 3 % of a branch point's time with the
  // 1024-sample stability grid, issue 14).
  const long M = total_, g = Mod(GridRate(h, 0), static_cast<int>(M));
  for (long s = 0, j = 0; s < M; ++s, j = j + g < M ? j + g : j + g - M)
    phases[s] = 2.0 * M_PI * (double(j) / double(M));
}

}  // namespace rmhb
