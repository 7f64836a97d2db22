#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "examples/example_model.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/simulate.h"

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
  const Model model = examples::LoadModelOrExample(a.model, ParseOverrides(a.set));
  if (!a.plot.empty()) plot::CheckPlotRequest(a.plot);
  if (a.json && a.csv.empty()) throw std::invalid_argument("--json needs --csv FILE for the trajectory");
  SimulateOptions options;
  if (a.t_end_given) options.t_end = a.t_end;
  if (a.dt_given) options.dt = a.dt;
  options.relative_tolerance = a.rtol;
  options.absolute_tolerance = a.atol;
  options.method = a.integrator == "bdf"     ? SimulateOptions::Method::kBdf
                   : a.integrator == "adams" ? SimulateOptions::Method::kAdams
                                             : SimulateOptions::Method::kAuto;
  const SimulateSummary s = Simulate(model, options);
  const integrators::IntegrationResult& r = s.result;
  if (!a.csv.empty()) {
    std::ofstream out(a.csv);
    if (!out) throw std::invalid_argument("--csv: cannot write '" + a.csv + "'");
    WriteCsv(out, model.state_names, r.trajectory);
  }
  if (!a.plot.empty() && r.trajectory.size() > 0) plot::PlotTrajectory(model, s, a.plot);
  json out = s.ToJson();
  if (!a.csv.empty()) out["csv"] = a.csv;
  if (!a.plot.empty()) out["plot"] = a.plot;
  if (a.json)
    std::cout << out.dump(1) << "\n";
  else if (a.csv.empty())
    WriteCsv(std::cout, model.state_names, r.trajectory);
  else
    std::printf("%s: %s\n%s -> %s\n", model.name.c_str(), model.equation.c_str(), s.BriefReport().c_str(), a.csv.c_str());
  if (!r.ok()) {
    std::fprintf(stderr, "rmhb: integration failed: %s\n", r.message.c_str());
    return kExitNotConverged;
  }
  return kExitOk;
}

}  // namespace rmhb::cli
