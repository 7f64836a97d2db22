#include "rmhb/seeding/identified_guess.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <fftw3.h>

#include "integrators/cvode_integrator.h"
#include "integrators/event_detection.h"
#include "integrators/ida_integrator.h"

namespace rmhb::seeding {
namespace {

using frequency_id::IdentificationSummary;

// A labelled line in the problem's coordinates.
struct Line {
  std::vector<int> label;
  double frequency = 0;      // label . w
  Eigen::VectorXd amplitude; // per channel
  Eigen::VectorXd phase;     // per channel, at t = 0
};

// The record's state on harmonics 0..order of w, fitted by least squares
// over its last periods (enough samples for a well-posed fit), in absolute
// time; harmonics above 0.8 Nyquist are left out (they alias).
std::vector<Line> FitHarmonics(const frequency_id::Signal& record, double w, int order,
                               Eigen::VectorXd* mean) {
  const int K = std::min(order, static_cast<int>(0.8 * M_PI / (w * record.dt)));
  if (K < 1) return {};
  const long rows = std::min<long>(record.num_samples(),
                                   std::max<long>(4 * (2 * K + 1), std::lround(4 * M_PI / (w * record.dt))));
  const long first = record.num_samples() - rows;
  Eigen::MatrixXd E(rows, 2 * K + 1);
  for (long n = 0; n < rows; ++n) {
    const double t = record.t0 + (first + n) * record.dt;
    E(n, 0) = 1;
    for (int k = 1; k <= K; ++k) E(n, 2 * k - 1) = std::cos(k * w * t), E(n, 2 * k) = std::sin(k * w * t);
  }
  const Eigen::MatrixXd c = E.colPivHouseholderQr().solve(record.samples.bottomRows(rows));
  *mean = c.row(0).transpose();
  std::vector<Line> lines(K);
  for (int k = 1; k <= K; ++k) {
    Line& line = lines[k - 1];
    line.label = {k};
    line.frequency = k * w;
    // a cos + b sin = A cos(k w t + phase)
    line.amplitude.resize(c.cols());
    line.phase.resize(c.cols());
    for (long ch = 0; ch < c.cols(); ++ch) {
      line.amplitude(ch) = std::hypot(c(2 * k - 1, ch), c(2 * k, ch));
      line.phase(ch) = std::atan2(-c(2 * k, ch), c(2 * k - 1, ch));
    }
  }
  return lines;
}

// Fourier coefficients of one period sampled uniformly (M rows), per channel:
// a_k (row 0 the mean) and b_k for k = 0 .. M/2 - 1, as
// y(t0 + tau) = a_0 + sum a_k cos(k w tau) + b_k sin(k w tau). FFTW's r2c.
void PeriodCoefficients(const frequency_id::Signal& period, Eigen::MatrixXd* a, Eigen::MatrixXd* b) {
  const int M = period.num_samples(), channels = period.num_channels(), K = M / 2;
  a->setZero(K, channels);
  b->setZero(K, channels);
  std::vector<double> in(M);
  std::vector<fftw_complex> out(M / 2 + 1);
  fftw_plan plan = fftw_plan_dft_r2c_1d(M, in.data(), out.data(), FFTW_ESTIMATE);
  for (int c = 0; c < channels; ++c) {
    for (int m = 0; m < M; ++m) in[m] = period.samples(m, c);
    fftw_execute(plan);
    (*a)(0, c) = out[0][0] / M;
    for (int k = 1; k < K; ++k) {
      (*a)(k, c) = 2 * out[k][0] / M;
      (*b)(k, c) = -2 * out[k][1] / M;
    }
  }
  fftw_destroy_plan(plan);
}

// The period's harmonics 1 .. min(order, M/2 - 1) as lines in absolute time.
std::vector<Line> PeriodHarmonics(const frequency_id::Signal& period, int order, Eigen::VectorXd* mean) {
  Eigen::MatrixXd a, b;
  PeriodCoefficients(period, &a, &b);
  const double w = 2 * M_PI / period.duration();
  *mean = a.row(0).transpose();
  std::vector<Line> lines;
  for (int k = 1; k <= std::min<int>(order, a.rows() - 1); ++k) {
    Line line;
    line.label = {k};
    line.frequency = k * w;
    line.amplitude.resize(a.cols());
    line.phase.resize(a.cols());
    for (long c = 0; c < a.cols(); ++c) {
      // a cos(k w tau) + b sin(k w tau) = A cos(k w t + phase), tau = t - t0
      line.amplitude(c) = std::hypot(a(k, c), b(k, c));
      line.phase(c) = std::atan2(-b(k, c), a(k, c)) - k * w * period.t0;
    }
    lines.push_back(std::move(line));
  }
  return lines;
}

// All integer d x d matrices with entries in [-range, range] and determinant
// +-1, for d <= 2; permutations only above (enumeration would explode).
std::vector<Eigen::MatrixXi> UnimodularCandidates(int d, int range) {
  std::vector<Eigen::MatrixXi> out;
  if (d == 1) {
    out.push_back(Eigen::MatrixXi::Identity(1, 1));
  } else if (d == 2) {
    for (int a = -range; a <= range; ++a)
      for (int b = -range; b <= range; ++b)
        for (int c = -range; c <= range; ++c)
          for (int e = -range; e <= range; ++e)
            if (std::abs(a * e - b * c) == 1) out.push_back((Eigen::Matrix2i() << a, b, c, e).finished());
  } else {
    std::vector<int> p(d);
    for (int i = 0; i < d; ++i) p[i] = i;
    do {
      Eigen::MatrixXi T = Eigen::MatrixXi::Zero(d, d);
      for (int i = 0; i < d; ++i) T(i, p[i]) = 1;
      out.push_back(T);
    } while (std::next_permutation(p.begin(), p.end()));
  }
  return out;
}

// The change of basis that brings the identified bases closest (relative) to
// the problem's frequencies, known ones matched exactly.
Eigen::MatrixXi ChooseCoordinates(const IdentificationSummary& id, const HarmonicBalanceProblem& problem) {
  const int d = static_cast<int>(problem.frequencies.size());
  Eigen::VectorXd w(d);
  for (int i = 0; i < d; ++i) w(i) = id.bases[i].frequency;
  double best = std::numeric_limits<double>::infinity();
  Eigen::MatrixXi chosen;
  for (const Eigen::MatrixXi& T : UnimodularCandidates(d, 3)) {
    const Eigen::VectorXd v = T.cast<double>() * w;
    double score = 0;
    for (int b = 0; b < d && score < best; ++b) {
      const bool unknown = !problem.unknown_frequency.empty() && problem.unknown_frequency[b];
      if (!(v(b) > 0)) score = std::numeric_limits<double>::infinity();
      else if (!unknown && std::abs(v(b) - problem.frequencies[b]) > 1e-12 * problem.frequencies[b])
        score = std::numeric_limits<double>::infinity();
      else score = std::max(score, std::abs(v(b) - problem.frequencies[b]) / problem.frequencies[b]);
    }
    if (score < best) best = score, chosen = T;
  }
  if (!std::isfinite(best))
    throw std::invalid_argument(
        "the identified bases do not match the model's known base frequencies in any integer "
        "coordinates");
  return chosen;
}

// The point conditions' residuals on a solution.
Eigen::VectorXd Conditions(const HarmonicBalanceProblem& problem, const HarmonicSolution& s) {
  const int n = s.num_variables();
  Eigen::VectorXd z(n), dz(n), r(problem.conditions.size());
  for (int j = 0; j < n; ++j) z(j) = s.Value(j, 0.0), dz(j) = s.Derivative(j, 0.0);
  for (size_t i = 0; i < problem.conditions.size(); ++i)
    r(i) = problem.conditions[i].function(z, dz, nullptr, nullptr);
  return r;
}

// Turns the unknown bases' angles to meet the point conditions: a scan of the
// angles (the conditions may have several roots: a maximum and a minimum for
// x'(0) = 0), then Gauss-Newton with finite differences from the best few
// grid points; the smallest residual wins, ties go to the smallest turn (a
// conservative record started on the conditions needs none).
std::vector<double> AlignPhases(const HarmonicBalanceProblem& problem, const HarmonicSolution& s) {
  const int d = static_cast<int>(problem.frequencies.size());
  std::vector<int> free;
  for (int b = 0; b < d; ++b)
    if (!problem.unknown_frequency.empty() && problem.unknown_frequency[b]) free.push_back(b);
  std::vector<double> none(d, 0.0);
  if (free.empty() || problem.conditions.empty() || free.size() > 2) return none;
  const int f = static_cast<int>(free.size());
  auto turn = [&](const Eigen::VectorXd& phi) {
    std::vector<double> p(d, 0.0);
    for (int i = 0; i < f; ++i) p[free[i]] = phi(i);
    return p;
  };
  auto conditions = [&](const Eigen::VectorXd& phi) { return Conditions(problem, s.Shifted(turn(phi))); };
  auto cost = [&](const Eigen::VectorXd& phi) { return conditions(phi).norm(); };
  // A record started on the conditions (a conservative motion) meets them
  // already, up to the truncation of the basis: no scan, no other root.
  const double at_zero = cost(Eigen::VectorXd::Zero(f));
  const bool started_on_conditions = at_zero <= 1e-5 * (1 + s.coefficients().cwiseAbs().maxCoeff());
  const int grid = f == 1 ? 256 : 32;
  std::vector<std::pair<double, Eigen::VectorXd>> scanned;
  if (started_on_conditions) scanned.push_back({at_zero, Eigen::VectorXd::Zero(f)});
  Eigen::VectorXd phi(f);
  const long total = started_on_conditions ? 0 : f == 1 ? grid : grid * grid;
  for (long g = 0; g < total; ++g) {
    phi(0) = 2 * M_PI * (g % grid) / grid;
    if (f == 2) phi(1) = 2 * M_PI * (g / grid) / grid;
    for (int i = 0; i < f; ++i) if (phi(i) > M_PI) phi(i) -= 2 * M_PI;
    scanned.push_back({cost(phi), phi});
  }
  std::sort(scanned.begin(), scanned.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  double best_cost = std::numeric_limits<double>::infinity();
  Eigen::VectorXd best = Eigen::VectorXd::Zero(f);
  const double scale = 1e-9 * std::max(1.0, scanned.front().first);
  for (size_t start = 0; start < std::min<size_t>(6, scanned.size()); ++start) {
    Eigen::VectorXd x = scanned[start].second;
    double c = scanned[start].first;
    for (int it = 0; it < 20 && c > 0; ++it) {
      const Eigen::VectorXd r = conditions(x);
      Eigen::MatrixXd J(r.size(), f);
      for (int i = 0; i < f; ++i) {
        Eigen::VectorXd h = Eigen::VectorXd::Zero(f);
        h(i) = 1e-6;
        J.col(i) = (conditions(x + h) - conditions(x - h)) / 2e-6;
      }
      const Eigen::VectorXd step = J.colPivHouseholderQr().solve(-r);
      double lambda = 1, next = c;
      Eigen::VectorXd y = x;
      for (; lambda > 1e-4; lambda *= 0.5) {
        y = x + lambda * step;
        next = cost(y);
        if (next < c) break;
      }
      if (!(next < c)) break;
      const bool small = (y - x).norm() < 1e-14;
      x = y, c = next;
      if (small) break;
    }
    for (int i = 0; i < f; ++i) x(i) = std::remainder(x(i), 2 * M_PI);
    const bool tie = std::abs(c - best_cost) <= scale;
    if ((c < best_cost && !tie) || (tie && x.norm() < best.norm())) best_cost = std::min(c, best_cost), best = x;
  }
  return turn(best);
}

}  // namespace

RecordOptions DefaultRecord(const std::vector<double>& w, int samples_per_period, double periods,
                            double beats) {
  if (w.empty() || samples_per_period < 4)
    throw std::invalid_argument("DefaultRecord: need frequencies and >= 4 samples per period");
  for (double v : w)
    if (!(v > 0) || !std::isfinite(v)) throw std::invalid_argument("DefaultRecord: frequencies must be > 0");
  const double w_max = *std::max_element(w.begin(), w.end());
  const double w_min = *std::min_element(w.begin(), w.end());
  RecordOptions r;
  double length = periods * 2 * M_PI / w_min;
  for (size_t i = 0; i < w.size(); ++i)
    for (size_t j = i + 1; j < w.size(); ++j)
      length = std::max(length, beats * 2 * M_PI / std::max(std::abs(w[i] - w[j]), 1e-12));
  r.transient = length / 9;  // a tenth of the whole integration
  r.t_end = r.transient + length;
  r.dt = 2 * M_PI / w_max / samples_per_period;
  r.integrator.relative_tolerance = 1e-13;
  r.integrator.absolute_tolerance = 1e-15;
  return r;
}

namespace {

// Uniform samples of [transient, t_end) from whichever integrator `integrate` runs.
frequency_id::Signal Record(
    const RecordOptions& o, std::vector<std::string> names,
    const std::function<integrators::IntegrationResult(const std::vector<double>&)>& integrate) {
  if (!(o.dt > 0) || !(o.transient >= 0) || !(o.t_end > o.transient) || !std::isfinite(o.t_end))
    throw std::invalid_argument("the record needs dt > 0 and 0 <= transient < t_end (got dt " +
                                std::to_string(o.dt) + ", transient " + std::to_string(o.transient) +
                                ", t_end " + std::to_string(o.t_end) + ")");
  const double count = std::floor((o.t_end - o.transient) / o.dt);
  if (count > 20e6) throw std::invalid_argument("the record would need " + std::to_string(count) + " samples");
  if (count < 64) throw std::invalid_argument("the record is too short: " + std::to_string(count) + " samples");
  const long n = static_cast<long>(count);
  std::vector<double> times(n);
  for (long i = 0; i < n; ++i) times[i] = o.transient + i * o.dt;
  const integrators::IntegrationResult r = integrate(times);
  if (!r.ok()) throw std::runtime_error("integration failed: " + r.message);
  frequency_id::Signal signal;
  signal.dt = o.dt;
  signal.t0 = o.transient;
  signal.samples = r.trajectory.states;
  signal.channel_names = std::move(names);
  return signal;
}

}  // namespace

frequency_id::Signal RecordTrajectory(const integrators::OdeSystem& system, const Eigen::VectorXd& y0,
                                      const RecordOptions& o, std::vector<std::string> names) {
  return Record(o, std::move(names), [&](const std::vector<double>& times) {
    return integrators::IntegrateOde(system, y0, 0.0, times, o.integrator);
  });
}

frequency_id::Signal RecordTrajectory(const integrators::DaeSystem& system, const Eigen::VectorXd& y0,
                                      const RecordOptions& o, std::vector<std::string> names) {
  return Record(o, std::move(names), [&](const std::vector<double>& times) {
    return integrators::IntegrateDae(system, y0, Eigen::VectorXd::Zero(y0.size()), 0.0, times, o.integrator);
  });
}

namespace {

// The guess from its spectral lines and mean (of the original state), with
// the autonomous bases' angles turned to meet the problem's conditions.
void Seed(const std::vector<Line>& lines, const Eigen::VectorXd& mean, const std::vector<double>& w,
          const HarmonicBalanceProblem& problem, const HarmonicBasis& basis, const StateToVariables& variables,
          int state_derivatives, IdentifiedGuess* out) {
  const int d = static_cast<int>(w.size());
  const int channels = static_cast<int>(mean.size());
  auto f = [&](const std::vector<double>& theta) {
    std::vector<Eigen::VectorXd> state(state_derivatives + 1, Eigen::VectorXd::Zero(channels));
    state[0] = mean;
    for (const Line& line : lines) {
      double arg = 0;
      for (int i = 0; i < d; ++i) arg += line.label[i] * theta[i];
      double scale = 1;
      for (int j = 0; j <= state_derivatives; ++j, scale *= line.frequency)
        for (int c = 0; c < channels; ++c)
          state[j](c) += scale * line.amplitude(c) * std::cos(arg + line.phase(c) + j * M_PI / 2);
    }
    return variables(theta, state);
  };
  HarmonicSolution guess = HarmonicSolution::FromAngles(basis, w, problem.system.variables(), f);
  out->phase_shift = AlignPhases(problem, guess);
  out->guess = guess.Shifted(out->phase_shift);
  if (!problem.conditions.empty())
    out->condition_residual = Conditions(problem, out->guess).cwiseAbs().maxCoeff();
}

}  // namespace

IdentifiedGuess GuessFromIdentification(const IdentificationSummary& id, const HarmonicBalanceProblem& problem,
                                        const HarmonicBasis& basis, const StateToVariables& variables,
                                        int state_derivatives, const frequency_id::Signal* record,
                                        const frequency_id::Signal* period) {
  const int d = static_cast<int>(problem.frequencies.size());
  if (!id.IsUsable()) throw std::invalid_argument("the identification is not usable: " + id.message);
  if (static_cast<int>(id.bases.size()) != d)
    throw std::invalid_argument("the identification found " + std::to_string(id.bases.size()) +
                                " base frequencies, the model has " + std::to_string(d));
  if (basis.num_bases() != d) throw std::invalid_argument("GuessFromIdentification: basis and problem differ");
  if (state_derivatives < 0) throw std::invalid_argument("GuessFromIdentification: state_derivatives < 0");

  IdentifiedGuess out{HarmonicSolution(basis, problem.frequencies,
                                       Eigen::MatrixXd::Zero(problem.system.num_variables(), basis.num_coefficients()),
                                       problem.system.variables()),
                      {}, {}, {}, {}, 0, 0, 0, 0};
  const Eigen::MatrixXi T = ChooseCoordinates(id, problem);
  // Labels transform contragrediently: l . w_id = l' . (T w_id) for l' = T^-T l.
  const Eigen::MatrixXd inverse_transpose = T.cast<double>().inverse().transpose();
  std::vector<double> w(d);
  for (int b = 0; b < d; ++b) {
    double value = 0, variance = 0;
    out.coordinates.emplace_back();
    for (int i = 0; i < d; ++i) {
      out.coordinates.back().push_back(T(b, i));
      value += T(b, i) * id.bases[i].frequency;
      variance += T(b, i) * T(b, i) * id.bases[i].uncertainty * id.bases[i].uncertainty;
    }
    const bool unknown = !problem.unknown_frequency.empty() && problem.unknown_frequency[b];
    w[b] = unknown ? value : problem.frequencies[b];
    out.frequencies.push_back(w[b]);
    out.uncertainties.push_back(unknown ? std::sqrt(variance) : 0.0);
  }

  std::vector<Line> lines;
  double energy = 0, on_basis = 0;
  for (const auto& c : id.components) {
    const double e = c.amplitude.squaredNorm();
    energy += e;
    if (!c.explained()) {
      ++out.lines_dropped;
      continue;
    }
    Eigen::VectorXd l(d);
    for (int i = 0; i < d; ++i) l(i) = c.label[i];
    const Eigen::VectorXd m = inverse_transpose * l;
    Line line;
    for (int i = 0; i < d; ++i) line.label.push_back(static_cast<int>(std::lround(m(i))));
    std::vector<int> negated(line.label);
    for (int& k : negated) k = -k;
    if (basis.Find(line.label) < 0 && basis.Find(negated) < 0) {
      ++out.lines_dropped;
      continue;
    }
    for (int i = 0; i < d; ++i) line.frequency += line.label[i] * w[i];
    line.amplitude = c.amplitude;
    line.phase = c.phase;
    lines.push_back(line);
    on_basis += e;
    ++out.lines_used;
  }
  out.energy_on_basis = energy > 0 ? on_basis / energy : 0;

  Eigen::VectorXd mean = id.mean;
  if (d == 1 && period) {
    lines = PeriodHarmonics(*period, basis.Reach(0), &mean);
    out.period_harmonics = static_cast<int>(lines.size());
    const bool unknown = !problem.unknown_frequency.empty() && problem.unknown_frequency[0];
    if (unknown) w[0] = out.frequencies[0] = 2 * M_PI / period->duration();
  } else if (d == 1 && record) {
    lines = FitHarmonics(*record, w[0], basis.Reach(0), &mean);
    out.fitted_harmonics = static_cast<int>(lines.size());
  }
  Seed(lines, mean, w, problem, basis, variables, state_derivatives, &out);
  return out;
}

IdentifiedGuess GuessFromPeriod(const HarmonicBalanceProblem& problem, const HarmonicBasis& basis,
                                const StateToVariables& variables, int state_derivatives,
                                const frequency_id::Signal& period) {
  if (problem.frequencies.size() != 1 || basis.num_bases() != 1 || problem.unknown_frequency.empty() ||
      !problem.unknown_frequency[0])
    throw std::invalid_argument("GuessFromPeriod: one unknown base frequency only");
  if (state_derivatives < 0) throw std::invalid_argument("GuessFromPeriod: state_derivatives < 0");
  const std::vector<double> w = {2 * M_PI / period.duration()};
  IdentifiedGuess out{HarmonicSolution(basis, w,
                                       Eigen::MatrixXd::Zero(problem.system.num_variables(), basis.num_coefficients()),
                                       problem.system.variables()),
                      w, {0.0}, {{1}}, {}, 0, 0, 0, 0};
  Eigen::VectorXd mean;
  const std::vector<Line> lines = PeriodHarmonics(period, basis.Reach(0), &mean);
  out.period_harmonics = static_cast<int>(lines.size());
  Seed(lines, mean, w, problem, basis, variables, state_derivatives, &out);
  return out;
}

std::string IdentifiedGuess::Report() const {
  std::ostringstream os;
  os.precision(3);
  const int d = static_cast<int>(frequencies.size());
  bool identity = true;
  for (int b = 0; b < d; ++b)
    for (int i = 0; i < d; ++i) identity = identity && coordinates[b][i] == (b == i);
  if (fitted_harmonics) os << fitted_harmonics << " harmonics fitted on the record; ";
  if (period_harmonics) os << period_harmonics << " harmonics of one period (its return to the section); ";
  os << lines_used << " labelled lines on the basis (" << 100 * energy_on_basis << "% of the line energy), "
     << lines_dropped << " left out";
  if (!identity) {
    os << "; coordinates:";
    for (int b = 0; b < d; ++b) {
      os << (b ? ", w" : " w") << b + 1 << " =";
      bool first = true;
      for (int i = 0; i < d; ++i) {
        if (!coordinates[b][i]) continue;
        os << (coordinates[b][i] < 0 ? " -" : first ? " " : " + ");
        if (std::abs(coordinates[b][i]) != 1) os << std::abs(coordinates[b][i]) << "*";
        os << "b" << i + 1;
        first = false;
      }
    }
  }
  bool turned = false;
  for (double p : phase_shift) turned = turned || p != 0;
  if (turned) {
    os << "; angles turned by";
    for (double p : phase_shift) os << " " << p;
  }
  os << "; conditions residual " << condition_residual;
  return os.str();
}

// How close the return must come to y0, relative to max(1, |y0|): a settled
// orbit returns to the integrator's accuracy, a torus' trajectory does not.
constexpr double kClosedReturn = 1e-6;

std::optional<frequency_id::Signal> OnePeriod(const integrators::OdeSystem& system, const Eigen::VectorXd& y0,
                                              double t0, double period_guess, int samples,
                                              const integrators::IntegratorOptions& options) {
  if (!(period_guess > 0) || samples < 8) throw std::invalid_argument("OnePeriod: period_guess > 0, samples >= 8");
  integrators::IntegrationResult info;
  const std::vector<double> returns = integrators::SectionReturns(system, y0, 1.2 * period_guess, options, &info);
  const auto close = std::find_if(returns.begin(), returns.end(),
                                  [&](double t) { return std::abs(t - period_guess) <= 0.2 * period_guess; });
  if (close == returns.end()) return std::nullopt;
  // Back at y0 (a periodic orbit), not merely near it (a torus' return).
  const Eigen::VectorXd back = info.trajectory.states.row(close - returns.begin()).transpose();
  if ((back - y0).lpNorm<Eigen::Infinity>() > kClosedReturn * std::max(1.0, y0.lpNorm<Eigen::Infinity>()))
    return std::nullopt;
  const double T = *close;
  std::vector<double> times(samples);
  for (int m = 0; m < samples; ++m) times[m] = m * T / samples;
  const integrators::IntegrationResult r = integrators::IntegrateOde(system, y0, 0.0, times, options);
  if (!r.ok()) return std::nullopt;
  frequency_id::Signal out;
  out.dt = T / samples;
  out.t0 = t0;
  out.samples = r.trajectory.states;
  return out;
}

int PeriodOrder(const frequency_id::Signal& period, double floor) {
  Eigen::MatrixXd a, b;
  PeriodCoefficients(period, &a, &b);
  Eigen::VectorXd size = Eigen::VectorXd::Zero(a.rows());
  for (long k = 1; k < a.rows(); ++k)
    for (long c = 0; c < a.cols(); ++c) size(k) = std::max(size(k), std::hypot(a(k, c), b(k, c)));
  const double largest = size.maxCoeff();
  int order = 1;
  for (long k = 1; k < size.size(); ++k)
    if (size(k) > floor * largest) order = static_cast<int>(k);
  return order;
}

}  // namespace rmhb::seeding
