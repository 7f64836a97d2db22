#ifndef RMHB_PLOT_FIGURES_H_
#define RMHB_PLOT_FIGURES_H_

// The pictures of the studies (rmhb/pipeline/), what `--plot FILE.png|svg`
// of each command draws; each throws like WritePlot (plot.h). The branch of
// a continuation: branch_plot.h.

#include <string>

#include "frequency_id/frequency_identification.h"
#include "frequency_id/signal.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/pipeline/convergence.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/pipeline/simulate.h"

namespace rmhb::plot {

// Two periods of the slowest base: the solution against CVODE started on it
// (the original equations, rtol 1e-13), their difference and the phase
// portrait (solve --plot, analyze --plot); a 2-torus also its section
// theta1 = 0 against the CVODE trajectory every period of the first base.
// Without original equations: the solution alone.
void PlotSolution(const Model& model, const HarmonicSolution& solution, const std::string& file);

// The windowed amplitude spectrum of the first channel, and every identified
// line at its refined frequency labelled with its combination (m, n)
// (identify --plot).
void PlotSpectrum(const frequency_id::Signal& signal, const frequency_id::IdentificationSummary& summary,
                  const std::string& file);

// Error against run time (log-log) and against order, one line per column
// (convergence --plot).
void PlotConvergence(const ConvergenceSummary& study, const std::string& file);

// The integrated states against time (simulate --plot).
void PlotTrajectory(const Model& model, const SimulateSummary& simulation, const std::string& file);

}  // namespace rmhb::plot

#endif  // RMHB_PLOT_FIGURES_H_
