#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "examples/example_model.h"
#include "rmhb/model/recast.h"
#include "rmhb/pipeline/convergence.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

// "5:25:5" (start:stop:step), "5:25" (step 1) or "5,10,25".
std::vector<int> ParseOrders(const std::string& text) {
  const std::vector<double> v = ParseNumberList(text, "--orders");
  for (double x : v)
    if (x != std::floor(x) || x < 1 || x > 100000)
      throw std::invalid_argument("--orders: '" + text + "' must hold whole numbers >= 1");
  std::vector<int> orders;
  if (text.find(':') != std::string::npos) {
    if (v.size() < 2 || v.size() > 3 || v[1] < v[0] || (v.size() == 3 && v[2] < 1))
      throw std::invalid_argument("--orders: expected start:stop[:step] with stop >= start, got '" + text + "'");
    for (int n = static_cast<int>(v[0]); n <= v[1]; n += v.size() == 3 ? static_cast<int>(v[2]) : 1)
      orders.push_back(n);
  } else {
    for (double x : v) orders.push_back(static_cast<int>(x));
  }
  if (orders.size() > 200) throw std::invalid_argument("--orders: at most 200 orders");
  return orders;
}

// The model file of a bundled example, for the symbolic (Taylor) variant:
// examples/models/<name>.yaml under the working directory or beside the
// build directory of this executable.
std::string TwinModelFile(const std::string& example) {
  std::vector<std::string> candidates = {"examples/models/" + example + ".yaml"};
  char exe[4096];
  const ssize_t n = readlink("/proc/self/exe", exe, sizeof(exe) - 1);
  if (n > 0) {
    std::string dir(exe, static_cast<size_t>(n));
    dir = dir.substr(0, dir.rfind('/'));
    candidates.push_back(dir + "/../examples/models/" + example + ".yaml");
  }
  for (const auto& c : candidates)
    if (access(c.c_str(), R_OK) == 0) return c;
  return "";
}

}  // namespace

void AddConvergenceOptions(CLI::App* app, ConvergenceArgs* a) {
  AddSolveSettings(app, &a->settings);
  // Per-solve choices become lists here: one column per method, solver and
  // condition scheme, one row per order.
  for (const char* name : {"--order", "--samples", "--method", "--solver", "--allow-aliasing"}) app->remove_option(app->get_option(name));
  app->add_option("--orders,--p", a->orders,
                  "Orders to solve: start:stop:step, start:stop or a list 5,10,25 (N for one base "
                  "frequency, p for two; default 5:25:5)");
  app->add_option("--methods", a->methods,
                  "Columns, comma-separated: rhb, hdhb, aft (the recast system), taylor (RHB on the "
                  "Taylor-expanded model, phi = --taylor), original (HB-AFT on the original equations, "
                  "no recast). Default: rhb,hdhb,aft, plus taylor,original when the recast needed "
                  "auxiliary variables");
  app->add_option("--solver", a->solvers,
                  "Nonlinear solvers, comma-separated: newton, lm, tikhonov, auto (default auto); "
                  "each adds a column per method");
  app->add_option("--conditions", a->conditions,
                  "Constraint schemes for the recast methods (METHOD.md s.5), comma-separated: model "
                  "(the model's own conditions, default), scheme1 (all constant terms balanced + "
                  "amplitude), scheme2 (auxiliaries pinned + amplitude), scheme3 (pinned + phase)");
  app->add_option("--taylor", a->taylor_order, "Taylor order of the taylor column (default 15)")
      ->check(CLI::Range(1, 60));
  app->add_option("--original-samples", a->original_samples,
                  "Samples M of the original column (default 0: the recast system's HB-AFT count "
                  "2^k >= 2 phi N + 1; the paper used 1024)")
      ->check(CLI::Range(0, 1 << 22));
  app->add_option("--repeat", a->repeat, "Solve each cell this many times; report the fastest (default 1)")
      ->check(CLI::Range(1, 1000));
  app->add_option("--max-seconds", a->max_seconds, "Time budget of each solve in seconds (default 60)")
      ->check(CLI::Range(0.001, 1e6));
  app->add_option("--plot", a->plot, "Draw error against run time (log-log) into FILE.png or FILE.svg");
  app->add_flag("--json", a->json, "The table as data: one entry per column with one row per order");
  app->footer(
      "Error: against the example's exact reference (the solution over a period, else the\n"
      "amplitude, else the frequency), otherwise against a CVODE trajectory of the original\n"
      "equations started on the solution. Time: the whole solve (order continuation included).\n"
      "Text cells: error, time in ms, samples M; '!' after the error marks a converged but\n"
      "NON-PHYSICAL solution (explained under the table; JSON \"physical\": false). The taylor\n"
      "column needs the model's equations:\n"
      "a model file, or for an example examples/models/<name>.yaml.\n"
      "Exit codes: 0 ok (also when some cells did not converge: they are reported), 1 usage,\n"
      "2 bad input, 3 no cell converged, 4 internal, 5 every converged cell non-physical.");
}

namespace {

// The study's options from the command line: every list item checked,
// naming the option.
ConvergenceOptions StudyOptions(const ConvergenceArgs& a, const std::vector<int>& orders,
                                const HarmonicBalanceOptions& base) {
  ConvergenceOptions o;
  o.orders = orders;
  o.solve = base;
  o.solve.solver.max_seconds = a.max_seconds;
  for (const auto& m : SplitList(a.methods)) o.methods.push_back(ParseStudyMethod(m));
  const std::vector<std::string> solvers = SplitList(a.solvers);
  if (!solvers.empty()) o.solvers.clear();
  for (const auto& name : solvers) o.solvers.push_back(ParseSolverMethod(name));
  const std::vector<std::string> schemes = SplitList(a.conditions);
  if (schemes.empty()) throw std::invalid_argument("--conditions: empty list");
  o.schemes.clear();
  for (const auto& c : schemes) o.schemes.push_back(ParseConstraintScheme(c));
  o.taylor_order = a.taylor_order;
  o.original_samples = a.original_samples;
  o.repeat = a.repeat;
  return o;
}

}  // namespace

int RunConvergence(const ConvergenceArgs& a) {
  const std::vector<int> orders = ParseOrders(a.orders);
  if (!a.plot.empty()) plot::CheckPlotRequest(a.plot);
  ModelSettings settings = a.settings;
  settings.solve.order = orders[0];
  PreparedSolve prepared = Prepare(settings);
  Model& source = prepared.model;
  // A bundled example's Taylor variant needs its equations: its model file.
  if (!source.definition && !source.from_file) {
    const std::string file = TwinModelFile(source.name);
    if (!file.empty()) source.definition = std::make_shared<const model::ModelDefinition>(model::LoadModelFile(file));
  }
  const ConvergenceOptions options = StudyOptions(a, orders, prepared.options);
  const ConvergenceSummary study = ConvergenceStudy(source, options);
  if (!a.plot.empty()) plot::PlotConvergence(study, a.plot);
  if (a.json) {
    json out = study.ToJson();
    out["model"] = a.settings.model;
    if (!a.plot.empty()) out["plot"] = a.plot;
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s", study.FullReport().c_str());
  }
  if (study.converged == 0) {
    std::fprintf(stderr, "rmhb: no solve converged\n");
    return kExitNotConverged;
  }
  if (study.physical == 0) {
    std::fprintf(stderr, "rmhb: every converged solve is NON-PHYSICAL\n");
    return kExitNonPhysical;
  }
  return kExitOk;
}

}  // namespace rmhb::cli
