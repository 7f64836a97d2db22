// Error of the identified base frequencies against run time, for several
// record lengths and window orders. Not a test: prints tables only.
//
//   frequency_id_benchmark [max_periods]   synthetic records (1-3), then 4
//   frequency_id_benchmark asym            only 4
//
// 4. The whole identification of the asymmetric pendulum (example
//    `asym-pendulum`): CVODE trajectory from the initial state + FFT +
//    refinement + base selection, timed, and the bases against the
//    RMHB-solved frequencies (beat basis p = 6, error 2e-10 against CVODE).
//    Rows vary what the time depends on: record length, samples per period,
//    CVODE tolerance, the line threshold.
//
// The record is a band-limited quasi-periodic signal with ~70 lines whose
// amplitudes fall by 0.12 per order |m| + |n| (two close bases, as in the
// tests). Three regimes:
//  1. the default pipeline: every line above 1e-10 is modelled, so the
//     result is exact to round-off whatever the record length;
//  2. a deliberately truncated model (max_components lines): the lines left
//     out bias the fit through the window's leakage, the classical NAFF
//     error that falls like T^-(2q+2) with the window order q;
//  3. white noise of std 1e-6: the error is statistical, ~T^-3/2, and grows
//     slowly with q (higher orders use less of the record).

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "examples/example_system.h"
#include "rmhb/seeding/identified_guess.h"
#include "frequency_id/frequency_identification.h"
#include "rmhb/harmonic_balance.h"

namespace {

using rmhb::frequency_id::IdentificationOptions;
using rmhb::frequency_id::IdentificationSummary;
using rmhb::frequency_id::IdentifyFrequencies;
using rmhb::frequency_id::Signal;

constexpr double kW1 = 0.9857123456789;
constexpr double kW2 = 0.9935987654321;
constexpr double kDt = 0.5;

Signal MakeSignal(int periods, double noise) {
  const int size = static_cast<int>(periods * 2.0 * M_PI / kW1 / kDt);
  Signal signal;
  signal.dt = kDt;
  signal.samples = Eigen::MatrixXd::Zero(size, 1);
  const double nyquist = M_PI / kDt;
  for (int m = -12; m <= 12; ++m) {
    for (int n = -12; n <= 12; ++n) {
      const int order = std::abs(m) + std::abs(n);
      const double f = m * kW1 + n * kW2;
      if (order == 0 || order > 12 || f <= 0.0 || f > 0.95 * nyquist) continue;
      const double amplitude = std::pow(0.12, order - 1);
      const double phase = 0.3 * m - 0.7 * n;
      for (int i = 0; i < size; ++i) {
        signal.samples(i, 0) += amplitude * std::cos(f * i * kDt + phase);
      }
    }
  }
  if (noise > 0.0) {
    std::mt19937_64 generator(17);
    std::normal_distribution<double> normal(0.0, noise);
    for (int i = 0; i < size; ++i) signal.samples(i, 0) += normal(generator);
  }
  return signal;
}

void Row(int periods, const Signal& signal, const IdentificationOptions& options) {
  IdentificationSummary summary;
  const auto start = std::chrono::steady_clock::now();
  IdentifyFrequencies(options, signal, &summary);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  double error = -1.0;
  if (summary.bases.size() == 2) {
    error = std::max(std::abs(summary.bases[0].frequency - kW1) / kW1,
                     std::abs(summary.bases[1].frequency - kW2) / kW2);
  }
  std::printf("  %7d  %7d  %5d  %3zu  %9.2e  %9.2e  %8.3f  %s\n", periods, signal.num_samples(),
              summary.window_order, summary.components.size(), error,
              summary.bases.empty() ? 0.0 : summary.bases[0].uncertainty / kW1, seconds,
              ToString(summary.status));
}

void Header(const char* title) {
  std::printf("\n%s\n  periods  samples  Hann^  lines  rel.error  rel.sigma  seconds  status\n",
              title);
}

// Section 4: one configuration of the pipeline.
struct PendulumRow {
  double beats;               // record length in beat periods
  int samples_per_period;
  double rtol;
  double relative_threshold;  // lines weaker than this (relative) are not modelled
  int max_components;
};

void AsymmetricPendulumRows() {
  using Clock = std::chrono::steady_clock;
  const rmhb::examples::ExampleSetup e = rmhb::examples::BuildExample("asym-pendulum");
  rmhb::HarmonicBalanceOptions o;
  o.order = e.default_order;
  o.shape = rmhb::BasisShape::kAdaptive;
  o.tolerance = 1e-11;
  const rmhb::HarmonicBalanceSummary solved = rmhb::SolveHarmonicBalance(e.problem, e.guess, o);
  if (!solved.converged()) {
    std::printf("reference solve failed\n%s", solved.FullReport().c_str());
    return;
  }
  const std::vector<double>& w = solved.solution->frequencies();
  std::printf("\n4. asymmetric pendulum: trajectory + identification, bases against RMHB at 1e-11:"
              " w = (%.15g, %.15g)\n"
              "  beats  spp  rtol    thresh  samples  lines  traj.s  ident.s (detect fit)  total.s  max|dw|   status\n",
              w[0], w[1]);
  // The paper's FFT estimates as the model's frequency guesses: they fix
  // only the record length and the coordinates, not the result.
  rmhb::HarmonicBalanceProblem problem = e.problem;
  problem.frequencies = {0.9857, 0.9935};
  const std::vector<PendulumRow> rows = {
      {20, 32, 1e-13, 1e-10, 64}, {8, 16, 1e-13, 1e-10, 64}, {4, 16, 1e-13, 1e-10, 64},
      {4, 12, 1e-13, 1e-8, 64},   {3, 12, 1e-13, 1e-8, 64},  {3, 12, 1e-11, 1e-8, 64},
      {3, 12, 1e-13, 1e-8, 32} /* rmhb analyze's default */, {3, 12, 1e-12, 1e-8, 32},  {3, 12, 1e-11, 1e-8, 32},
      {3, 10, 1e-12, 1e-8, 32},   {3, 12, 1e-12, 1e-8, 24},  {2.5, 12, 1e-12, 1e-8, 32}};
  for (const PendulumRow& row : rows) {
    rmhb::seeding::RecordOptions record =
        rmhb::seeding::DefaultRecord(problem.frequencies, row.samples_per_period, 200, row.beats);
    record.transient = 0;  // a conservative motion from its initial state: no transient
    record.t_end *= 0.9;
    record.integrator.relative_tolerance = row.rtol;
    record.integrator.absolute_tolerance = row.rtol * 1e-2;
    const auto start = Clock::now();
    const Signal signal = rmhb::seeding::RecordTrajectory({4, e.original.rhs}, e.original.initial_state, record);
    const double trajectory = std::chrono::duration<double>(Clock::now() - start).count();
    IdentificationOptions options;
    options.relative_threshold = row.relative_threshold;
    options.max_components = row.max_components;
    IdentificationSummary summary;
    IdentifyFrequencies(options, signal, &summary);
    const double total = std::chrono::duration<double>(Clock::now() - start).count();
    double error = -1;
    try {
      const rmhb::seeding::IdentifiedGuess seed = rmhb::seeding::GuessFromIdentification(
          summary, problem, rmhb::HarmonicBasis::Diamond(2, 2), [](const std::vector<double>&, const std::vector<Eigen::VectorXd>& y) { return y[0]; });
      error = std::max(std::abs(seed.frequencies[0] - w[0]), std::abs(seed.frequencies[1] - w[1]));
    } catch (const std::exception& ex) {
      std::printf("  (%s)\n", ex.what());
    }
    std::printf("  %5.1f  %3d  %5.0e  %6.0e  %7d  %5zu  %6.3f  %7.3f (%5.3f %5.3f)  %7.3f  %8.1e  %s\n",
                row.beats, row.samples_per_period, row.rtol, row.relative_threshold, signal.num_samples(),
                summary.components.size(), trajectory, total - trajectory, summary.detection_seconds,
                summary.fitting_seconds, total, error,
                ToString(summary.status));
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "asym") {
    AsymmetricPendulumRows();
    return 0;
  }
  const int max_periods = argc > 1 ? std::atoi(argv[1]) : 4000;
  std::vector<int> lengths;
  for (int periods = 125; periods <= max_periods; periods *= 2) lengths.push_back(periods);

  Header("1. default pipeline (automatic window order), noise-free");
  for (int periods : lengths) Row(periods, MakeSignal(periods, 0.0), IdentificationOptions());

  Header("2. truncated model: 12 lines only, the rest leaks; forced window orders");
  for (int periods : lengths) {
    const Signal signal = MakeSignal(periods, 0.0);
    for (int order : {1, 2, 3, 4, 6}) {
      IdentificationOptions options;
      options.window_order = order;
      options.max_components = 12;
      Row(periods, signal, options);
    }
  }

  Header("3. white noise, std 1e-6; forced window orders");
  for (int periods : lengths) {
    const Signal signal = MakeSignal(periods, 1e-6);
    for (int order : {1, 2, 4}) {
      IdentificationOptions options;
      options.window_order = order;
      Row(periods, signal, options);
    }
  }
  AsymmetricPendulumRows();
  return 0;
}
