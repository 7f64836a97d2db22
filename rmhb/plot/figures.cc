#include "rmhb/plot/figures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "frequency_id/spectrum.h"
#include "integrators/cvode_integrator.h"
#include "rmhb/plot/plot.h"

namespace rmhb::plot {

namespace {

// The original equations from the solution's state at t = 0, sampled at times.
integrators::IntegrationResult OriginalTrajectory(const Model& source, const HarmonicSolution& sol,
                                                  const std::vector<double>& times, double relative_tolerance) {
  integrators::IntegratorOptions io;
  io.method = source.stiff ? integrators::IntegratorOptions::Method::kBdf : integrators::IntegratorOptions::Method::kAdams;
  io.relative_tolerance = relative_tolerance;
  io.absolute_tolerance = 1e-2 * relative_tolerance;
  return integrators::IntegrateOde(source.original(sol.frequencies()), source.state(sol, 0.0), 0.0, times, io);
}

// A 2-torus cut at theta1 = 0: the closed curve z(0, theta2) of the
// solution, and the original equations' trajectory from its state at t = 0
// sampled every period 2 pi / w1 of the first base (a stroboscopic map:
// theta1 = 2 pi k there), whose points fall on the curve when the torus is
// the attractor or invariant set it claims to be.
PlotPanel TorusSection(const Model& source, const HarmonicSolution& sol) {
  PlotPanel section{"torus section theta1 = 0: harmonic balance (line) against CVODE every 2 pi / w1 (points)",
                    source.state_names[0], source.state_names[1], false, false, {}};
  PlotSeries curve{"HB z(0, theta2)", {}, {}, PlotSeries::Style::kLines, {}};
  for (int i = 0; i <= 400; ++i) {
    const Eigen::VectorXd y = source.state(sol.Shifted({0.0, 2 * M_PI * i / 400}), 0.0);
    curve.x.push_back(y(0));
    curve.y.push_back(y(1));
  }
  const double T1 = 2 * M_PI / sol.frequencies()[0];
  std::vector<double> times;
  for (int k = 0; k < 400; ++k) times.push_back(k * T1);
  const integrators::IntegrationResult r = OriginalTrajectory(source, sol, times, 1e-12);
  PlotSeries points{"CVODE, 400 periods of w1", {}, {}, PlotSeries::Style::kPoints, {}};
  for (int i = 0; i < r.trajectory.size(); ++i)
    points.x.push_back(r.trajectory.states(i, 0)), points.y.push_back(r.trajectory.states(i, 1));
  section.series = {curve, points};
  return section;
}

}  // namespace

void PlotSolution(const Model& source, const HarmonicSolution& sol, const std::string& file) {
  const double period = 2 * M_PI / *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
  std::vector<double> times(801);
  for (size_t i = 0; i < times.size(); ++i) times[i] = 2 * period * i / (times.size() - 1);
  const int n = source.original ? static_cast<int>(source.state_names.size()) : 0;
  std::vector<std::vector<double>> hb(n, std::vector<double>(times.size()));
  for (size_t i = 0; i < times.size() && n; ++i) {
    const Eigen::VectorXd y = source.state(sol, times[i]);
    for (int j = 0; j < n; ++j) hb[j][i] = y(j);
  }
  PlotPanel response{"time response: harmonic balance (lines) against CVODE (points)", "t", "state", false, false, {}};
  PlotPanel error{"|harmonic balance - CVODE|", "t", "error", false, true, {}};
  PlotPanel phase{"phase portrait", n ? source.state_names[0] : "", n > 1 ? source.state_names[1] : "", false, false, {}};
  if (n) {
    const integrators::IntegrationResult r = OriginalTrajectory(source, sol, times, 1e-13);
    for (int j = 0; j < n; ++j) {
      PlotSeries line{source.state_names[j] + " (HB)", times, hb[j], PlotSeries::Style::kLines, {}};
      PlotSeries ref{source.state_names[j] + " (CVODE)", {}, {}, PlotSeries::Style::kPoints, {}};
      PlotSeries diff{source.state_names[j], {}, {}, PlotSeries::Style::kLines, {}};
      for (int i = 0; i < r.trajectory.size(); i += 8) ref.x.push_back(r.trajectory.times[i]), ref.y.push_back(r.trajectory.states(i, j));
      for (int i = 0; i < r.trajectory.size(); ++i) {
        diff.x.push_back(r.trajectory.times[i]);
        diff.y.push_back(std::abs(hb[j][i] - r.trajectory.states(i, j)));
      }
      response.series.push_back(line);
      response.series.push_back(ref);
      error.series.push_back(diff);
    }
    if (n > 1) phase.series.push_back({"HB", hb[0], hb[1], PlotSeries::Style::kLines, {}});
  } else {  // no original system: the solution alone
    for (int j = 0; j < sol.num_variables(); ++j) {
      if (sol.variables()[j].role == VariableRole::kAuxiliary) continue;
      PlotSeries line{sol.variables()[j].name, times, {}, PlotSeries::Style::kLines, {}};
      for (double t : times) line.y.push_back(sol.Value(j, t));
      response.series.push_back(line);
    }
    response.title = "time response (no original ODE to compare with: " + source.original_error + ")";
  }
  Plot plot{source.name + ": " + source.equation, {response}};
  if (n) plot.panels.push_back(error);
  if (n > 1) plot.panels.push_back(phase);
  if (n > 1 && sol.frequencies().size() == 2) plot.panels.push_back(TorusSection(source, sol));
  WritePlot(plot, file);
}

void PlotSpectrum(const frequency_id::Signal& signal, const frequency_id::IdentificationSummary& summary,
                  const std::string& file) {
  frequency_id::SampleGrid grid;
  grid.t0 = signal.t0;
  grid.dt = signal.dt;
  grid.size = static_cast<int>(signal.samples.rows());
  frequency_id::SpectrumAnalyzer analyzer(grid, frequency_id::Window(summary.window_order > 0 ? summary.window_order : 2));
  const Eigen::VectorXd& amplitude = analyzer.Compute(signal.samples.col(0));
  double top = 0;
  for (const auto& c : summary.components) top = std::max(top, c.frequency);
  PlotSeries spectrum{"windowed FFT, " + (summary.channel_names.empty() ? std::string("channel 1") : summary.channel_names[0]),
                      {}, {}, PlotSeries::Style::kLines, {}};
  for (int k = 1; k < analyzer.num_bins(); ++k) {
    if (analyzer.BinFrequency(k) > 1.2 * top + 1) break;
    spectrum.x.push_back(analyzer.BinFrequency(k));
    spectrum.y.push_back(amplitude(k));
  }
  PlotSeries lines{"identified lines (m, n)", {}, {}, PlotSeries::Style::kImpulses, {}};
  for (const auto& c : summary.components) {
    lines.x.push_back(c.frequency);
    lines.y.push_back(c.amplitude.size() ? c.amplitude(0) : 0.0);
    std::string label = "(";
    for (size_t i = 0; i < c.label.size(); ++i) label += (i ? "," : "") + std::to_string(c.label[i]);
    lines.labels.push_back(c.label.empty() ? "?" : label + ")");
  }
  std::string bases;
  for (const auto& b : summary.bases) {
    char w[32];
    std::snprintf(w, sizeof w, "%.10g", b.frequency);
    bases += (bases.empty() ? "" : ", ") + std::string(w);
  }
  Plot plot{"frequency identification: bases " + bases, {}};
  plot.panels.push_back({"amplitude spectrum with labelled combination tones", "angular frequency [rad/time]",
                         "amplitude", false, true, {spectrum, lines}});
  WritePlot(plot, file);
}

void PlotConvergence(const ConvergenceSummary& study, const std::string& file) {
  Plot plot{study.model_name + ": " + study.equation, {}};
  PlotPanel speed{"error against run time", "run time [s]", "error: " + study.error_measure, true, true, {}};
  PlotPanel order{"error against order", study.bases == 1 ? "order N" : "order p", "error", false, true, {}};
  for (const auto& col : study.columns) {
    PlotSeries s{col.name, {}, {}, PlotSeries::Style::kLinesPoints, {}}, o = s;
    for (size_t i = 0; i < study.orders.size(); ++i) {
      if (col.cells[i].status != "converged") continue;
      s.x.push_back(col.cells[i].seconds), s.y.push_back(col.cells[i].error);
      o.x.push_back(study.orders[i]), o.y.push_back(col.cells[i].error);
    }
    speed.series.push_back(s);
    order.series.push_back(o);
  }
  plot.panels = {speed, order};
  WritePlot(plot, file);
}

void PlotTrajectory(const Model& model, const SimulateSummary& s, const std::string& file) {
  const integrators::IntegrationResult& r = s.result;
  char tolerance[32];
  std::snprintf(tolerance, sizeof tolerance, "%g", s.relative_tolerance);
  Plot plot{model.name + ": " + model.equation + " (" + r.solver + ", rtol " + tolerance + ")", {}};
  PlotPanel panel{"time response from the initial state", "t", "state", false, false, {}};
  for (int j = 0; j < r.trajectory.dimension(); ++j) {
    const Eigen::VectorXd c = r.trajectory.Component(j);
    panel.series.push_back({model.state_names[j], r.trajectory.times, std::vector<double>(c.data(), c.data() + c.size()),
                            PlotSeries::Style::kLines, {}});
  }
  plot.panels.push_back(panel);
  WritePlot(plot, file);
}

}  // namespace rmhb::plot
