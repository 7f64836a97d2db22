#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "rmhb/sweep/grid_sweep.h"
#include "rmhb/version.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
using namespace rmhb::sweep;
namespace fs = std::filesystem;

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// What changes results: the fingerprint ties a journal to its sweep.
json ResultOptions(const SweepArgs& a, const SweepOptions& o) {
  return {{"order", o.solve.order},       {"method", a.settings.solve.method}, {"samples", a.settings.solve.samples},
          {"solver", a.settings.solve.solver},  {"scaling", a.settings.solve.scaling},
          {"max_iterations", a.settings.solve.max_iterations}, {"residual_tol", a.settings.solve.residual_tol},
          {"frequencies", a.settings.solve.frequencies}, {"starts", o.starts}, {"range", a.range},
          {"seed", o.seed},               {"stability", o.stability},   {"cluster_tolerance", o.cluster_tolerance}};
}

void PlotMap(const SweepArgs& a, const ParameterGrid& grid, const std::vector<json>& points) {
  const auto& axes = grid.axes();
  auto value = [&](const json& p) {
    if (a.plot_value == "count") return static_cast<double>(p.at("solutions").size());
    double peak = NAN;
    for (const json& s : p.at("solutions")) peak = std::isnan(peak) ? s.at("amplitude").get<double>()
                                                                      : std::max(peak, s.at("amplitude").get<double>());
    return peak;
  };
  plot::HeatMap map;
  map.title = a.settings.model + ": " + (a.plot_value == "count" ? "number of solutions" : "largest amplitude");
  map.x_label = axes[0].name;
  map.z_label = a.plot_value;
  for (int i = 0; i < axes[0].count; ++i) map.x.push_back(axes[0].Value(i));
  if (axes.size() == 2) {
    map.y_label = axes[1].name;
    for (int j = 0; j < axes[1].count; ++j) map.y.push_back(axes[1].Value(j));
  } else {
    map.y = {0};
  }
  for (const json& p : points) map.z.push_back(value(p));
  plot::WriteHeatMap(map, a.plot);
}

}  // namespace

int RunSweep(const SweepArgs& a, int rank, int ranks) {
  if (a.settings.solve.tol > 0) throw std::invalid_argument("--tol does not apply to sweep: give --order");
  std::vector<GridAxis> axes;
  for (const std::string& text : a.grid) axes.push_back(ParseGridAxis(text));
  const ParameterGrid grid(std::move(axes));
  if (!a.plot.empty()) {
    plot::CheckPlotRequest(a.plot);
    if (grid.axes().size() > 2) throw std::invalid_argument("--plot draws grids of one or two axes");
  }
  const std::vector<double> range = ParseNumberList(a.range, "--range");
  if (range.size() != 2 || !(range[0] < range[1]))
    throw std::invalid_argument("--range expects lo:hi with lo < hi, got '" + a.range + "'");
  const PreparedSolve prepared = Prepare(a.settings, AtValues(grid, grid.Values(0)));
  SweepOptions options;
  options.solve = prepared.options;
  options.starts = a.starts;
  options.low = range[0];
  options.high = range[1];
  options.seed = a.seed;
  options.stability = !a.no_stability;
  if (const std::string error = options.IsValid(); !error.empty()) throw std::invalid_argument(error);

  GridSweepOptions run;
  run.sweep = options;
  run.out = a.out;
  run.resume = a.resume;
  run.keep_journal = a.keep_journal;
  run.log = a.log;
  run.info.software = "rmhb " RMHB_VERSION_STRING;
  run.info.model = a.settings.model;
  if (prepared.model.from_file) run.info.model_text = ReadFile(a.settings.model);
  for (const std::string& s : a.settings.set) run.info.parameters += (run.info.parameters.empty() ? "" : " ") + s;
  run.info.options = ResultOptions(a, options).dump();
  for (const GridAxis& x : grid.axes()) run.info.options += " " + x.name;
  const GridSweepSummary summary = SweepGrid(prepared.model, prepared.guess, grid, run, rank, ranks);
  if (rank != 0) return kExitOk;
  if (!a.plot.empty()) PlotMap(a, grid, summary.point_records);
  if (a.json)
    std::cout << summary.ToJson().dump(2) << "\n";
  else
    std::printf("%s", summary.FullReport().c_str());
  return kExitOk;
}

}  // namespace rmhb::cli
