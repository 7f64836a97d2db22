#include "rmhb/cli/simulate_command.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "integrators/cvode_integrator.h"
#include "integrators/ida_integrator.h"
#include "rmhb/cli/commands.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/plot.h"
#include "rmhb/cli/problem_source.h"
#include "rmhb/cli/solve_setup.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

void WriteCsv(std::ostream& out, const std::vector<std::string>& names, const integrators::Trajectory& tr) {
  out.precision(17);
  out << "t";
  for (const auto& n : names) out << "," << n;
  out << "\n";
  for (int i = 0; i < tr.size(); ++i) {
    out << tr.times[i];
    for (int j = 0; j < tr.dimension(); ++j) out << "," << tr.states(i, j);
    out << "\n";
  }
}

}  // namespace

void AddSimulateOptions(CLI::App* app, SimulateArgs* a) {
  app->add_option("model", a->model, "Example name (see `rmhb list`) or model file")->required();
  app->add_option("--set", a->set, "Override a parameter: --set name=value (repeatable)");
  app->add_option("--t-end", a->t_end, "End time (default: 20 periods of the slowest base frequency)")
      ->each([a](const std::string&) { a->t_end_given = true; });
  app->add_option("--dt", a->dt, "Output spacing (default: 1/64 of the fastest period)")
      ->each([a](const std::string&) { a->dt_given = true; });
  app->add_option("--rtol", a->rtol, "Relative tolerance of CVODE (default 1e-12)");
  app->add_option("--atol", a->atol, "Absolute tolerance of CVODE (default 1e-14)");
  app->add_option("--integrator", a->integrator,
                  "adams (non-stiff), bdf (stiff) or auto (the model's own choice, default); a DAE\n"
                  "model (algebraic equations) is always integrated by IDA's BDF")
      ->check(CLI::IsMember({"auto", "adams", "bdf"}));
  app->add_option("--csv", a->csv,
                  "Write t and every state to this CSV file (default: CSV on standard output)");
  app->add_option("--plot", a->plot, "Draw the time response into FILE.png or FILE.svg (gnuplot)");
  app->add_flag("--json", a->json, "Machine-readable summary (needs --csv for the data)");
  app->footer(
      "Starts from the model's initial state (for a model without one: its starting guess at\n"
      "t = 0, which meets its conditions to round-off).\n"
      "A model with algebraic equations (a DAE) is integrated by SUNDIALS IDA, which first\n"
      "makes the algebraic states consistent with the initial state (IDACalcIC).\n"
      "Exit codes: 0 ok, 1 usage, 2 bad input (unknown model/parameter, bad value, model\n"
      "that cannot be integrated, gnuplot missing for --plot), 3 the integration stopped\n"
      "before --t-end (SUNDIALS' message; the rows reached are written), 4 internal.");
}

int RunSimulate(const SimulateArgs& a) {
  const ProblemSource source = LoadProblem(a.model, ParseOverrides(a.set));
  if (!source.original && !source.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + source.original_error);
  if (!a.plot.empty()) CheckPlotRequest(a.plot);
  if (a.json && a.csv.empty()) throw std::invalid_argument("--json needs --csv FILE for the trajectory");
  const std::vector<double>& w = source.problem.frequencies;
  const double w_min = *std::min_element(w.begin(), w.end());
  const double w_max = *std::max_element(w.begin(), w.end());
  const double t_end = a.t_end_given ? a.t_end : 20 * 2 * M_PI / w_min;
  const double dt = a.dt_given ? a.dt : 2 * M_PI / w_max / 64;
  if (!(t_end > 0) || !std::isfinite(t_end)) throw std::invalid_argument("--t-end must be a finite number > 0");
  if (!(dt > 0) || !std::isfinite(dt)) throw std::invalid_argument("--dt must be a finite number > 0");
  if (!(a.rtol > 0) || !(a.atol > 0) || !std::isfinite(a.rtol) || !std::isfinite(a.atol))
    throw std::invalid_argument("--rtol and --atol must be finite numbers > 0");
  const double count = std::floor(t_end / dt + 1e-9) + 1;
  if (count > 5e7) throw std::invalid_argument("--t-end/--dt would write " + std::to_string(count) + " rows (at most 5e7)");
  std::vector<double> times(static_cast<size_t>(count));
  for (size_t i = 0; i < times.size(); ++i) times[i] = i * dt;

  integrators::IntegratorOptions io;
  const bool bdf = a.integrator == "bdf" || (a.integrator == "auto" && source.stiff);
  io.method = bdf ? integrators::IntegratorOptions::Method::kBdf : integrators::IntegratorOptions::Method::kAdams;
  io.relative_tolerance = a.rtol;
  io.absolute_tolerance = a.atol;
  // A model with algebraic equations goes to IDA, which makes y'(0) and the
  // algebraic part of the initial state consistent (IDACalcIC) first.
  const integrators::IntegrationResult r = SimulateOriginal(source, w, source.initial_state, times, io);

  if (!a.csv.empty()) {
    std::ofstream out(a.csv);
    if (!out) throw std::invalid_argument("--csv: cannot write '" + a.csv + "'");
    WriteCsv(out, source.state_names, r.trajectory);
  }
  if (!a.plot.empty() && r.trajectory.size() > 0) {
    char tolerance[32];
    std::snprintf(tolerance, sizeof tolerance, "%g", a.rtol);
    Plot plot{source.name + ": " + source.equation + " (" + r.solver + ", rtol " + tolerance + ")", {}};
    PlotPanel panel{"time response from the initial state", "t", "state", false, false, {}};
    for (int j = 0; j < r.trajectory.dimension(); ++j) {
      const Eigen::VectorXd c = r.trajectory.Component(j);
      panel.series.push_back({source.state_names[j], r.trajectory.times, std::vector<double>(c.data(), c.data() + c.size()), PlotSeries::Style::kLines, {}});
    }
    plot.panels.push_back(panel);
    WritePlot(plot, a.plot);
  }
  json out{{"status", r.ok() ? "ok" : "failed"},
           {"message", r.message},
           {"integrator", r.solver},
           {"rtol", a.rtol},
           {"atol", a.atol},
           {"t_end", t_end},
           {"dt", dt},
           {"rows", r.trajectory.size()},
           {"steps", r.steps},
           {"rhs_evaluations", r.rhs_evaluations},
           {"seconds", r.seconds},
           {"states", source.state_names}};
  json initial = json::array(), last = json::array();
  for (int j = 0; j < source.initial_state.size(); ++j) initial.push_back(Number(source.initial_state(j)));
  if (r.trajectory.size() > 0)
    for (int j = 0; j < r.trajectory.dimension(); ++j) last.push_back(Number(r.trajectory.states(r.trajectory.size() - 1, j)));
  out["initial_state"] = initial;
  out["final_state"] = last;
  if (!a.csv.empty()) out["csv"] = a.csv;
  if (!a.plot.empty()) out["plot"] = a.plot;
  if (a.json) {
    std::cout << out.dump(1) << "\n";
  } else if (a.csv.empty()) {
    WriteCsv(std::cout, source.state_names, r.trajectory);
  } else {
    std::printf("%s: %s\n%s, rtol %g, atol %g: %d rows to t = %g in %ld steps, %.1f ms -> %s\n",
                source.name.c_str(), source.equation.c_str(), r.solver.c_str(), a.rtol, a.atol,
                r.trajectory.size(), r.trajectory.size() ? r.trajectory.times.back() : 0.0, r.steps,
                r.seconds * 1e3, a.csv.c_str());
  }
  if (!r.ok()) {
    std::fprintf(stderr, "rmhb: integration failed: %s\n", r.message.c_str());
    return kExitNotConverged;
  }
  return kExitOk;
}

}  // namespace rmhb::cli
