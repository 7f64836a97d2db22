#include "rmhb/cli/convergence_command.h"

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

#include "integrators/trajectory_validation.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/cli/plot.h"
#include "rmhb/cli/problem_source.h"
#include "rmhb/model/recast.h"
#include "rmhb/model/taylor_expansion.h"
#include "rmhb/pointwise_collocation.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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

// The paper's constraint schemes for a conservative system (METHOD.md s.5),
// on the recast problem whose first conditions are the user's (amplitude,
// then phase) and the rest pin auxiliaries:
//   scheme1: every constant term balanced, the amplitude condition only;
//   scheme2: the auxiliaries pinned, amplitude condition;
//   scheme3: the auxiliaries pinned, phase condition.
HarmonicBalanceProblem WithConditions(const ProblemSource& source, const std::string& scheme) {
  HarmonicBalanceProblem p = source.problem;
  if (scheme == "model") return p;
  const int users = source.num_user_conditions;
  if (users < (scheme == "scheme3" ? 2 : 1))
    throw std::invalid_argument("--conditions " + scheme + ": the model has " + std::to_string(users) +
                                " condition(s) of its own; the schemes need amplitude and phase conditions");
  const std::vector<PointCondition> all = source.problem.conditions;
  std::vector<PointCondition> pins(all.begin() + users, all.end());
  if (scheme == "scheme1") {
    PolynomialSystem balanced;
    for (const auto& v : p.system.variables()) balanced.AddVariable(v.name, v.role, v.definition);
    for (const auto& e : p.system.equations()) balanced.AddEquation(e.lhs, true);
    p.system = balanced;
    p.conditions = {all[0]};
  } else {
    p.conditions = {all[scheme == "scheme2" ? 0 : 1]};
    p.conditions.insert(p.conditions.end(), pins.begin(), pins.end());
  }
  return p;
}

// A condition on the recast variables as one on the original states y:
// z and z' of a recast variable are read off the state that holds it.
PointCondition OnStates(const PointCondition& c, const std::vector<model::StateSource>& sources, int variables) {
  return {c.description, [c, sources, variables](const Eigen::VectorXd& y, const Eigen::VectorXd& dy,
                                                 Eigen::VectorXd* gy, Eigen::VectorXd* gdy) {
            Eigen::VectorXd z = Eigen::VectorXd::Zero(variables), dz = z, gz = z, gdz = z;
            for (size_t s = 0; s < sources.size(); ++s)
              (sources[s].derivative == 0 ? z : dz)(sources[s].variable) = y(static_cast<long>(s));
            for (size_t s = 0; s < sources.size(); ++s)
              if (sources[s].derivative == 0) dz(sources[s].variable) = dy(static_cast<long>(s));
            const double r = c.function(z, dz, gy ? &gz : nullptr, gy ? &gdz : nullptr);
            if (gy)
              for (size_t s = 0; s < sources.size(); ++s) {
                const int v = sources[s].variable;
                if (sources[s].derivative == 0) {
                  (*gy)(static_cast<long>(s)) += gz(v);
                  (*gdy)(static_cast<long>(s)) += gdz(v);
                } else {
                  (*gy)(static_cast<long>(s)) += gdz(v);
                }
              }
            return r;
          }};
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

struct Cell {
  std::string status = "skipped";
  std::string message;
  int samples = 0;
  int iterations = 0;
  double residual = kNaN, seconds = kNaN;
  double reciprocal_condition = kNaN;  // of the final Jacobian (SolverSummary)
  double frequency_error = kNaN, amplitude_error = kNaN, max_error = kNaN, trajectory_error = kNaN;
  double error = kNaN;  // the table's measure
  bool physical = true;  // HarmonicBalanceSummary::physical of a converged cell
  std::string non_physical;
  double definition_error = kNaN;
};

using StateOf = std::function<Eigen::VectorXd(const HarmonicSolution&, double)>;
using SolveAt = std::function<HarmonicBalanceSummary(int order)>;

struct Column {
  std::string name, method, solver, conditions;
  SolveAt solve;
  StateOf state;
  std::string unavailable;  // why this column has no numbers
  std::vector<Cell> cells;
};

// Which error the table shows: the strongest the reference allows.
std::string ErrorMeasure(const ProblemSource& source, const std::string& first_variable) {
  const ExactReference& ref = source.reference;
  if (ref.solution) return "max over one period of |" + first_variable + "(t) - exact|";
  if (ref.has_amplitude()) return "|amplitude of " + ref.amplitude_variable + " - exact|";
  if (ref.has_frequency()) return "|w - exact|";
  return std::string("max state error over one period against ") +
         (source.original_dae ? "IDA (BDF, rtol 1e-14)" : source.stiff ? "CVODE (BDF, rtol 1e-12)" : "CVODE (Adams, rtol 1e-13)") +
         " started on the solution";
}

void Measure(const ProblemSource& source, const HarmonicSolution& sol, const StateOf& state, Cell* cell) {
  const ExactReference& ref = source.reference;
  const ReferenceErrors errors = ErrorsAgainst(ref, sol);
  if (ref.has_frequency()) cell->frequency_error = std::abs(errors.frequency);
  if (ref.has_amplitude() && sol.IndexOf(ref.amplitude_variable) >= 0) cell->amplitude_error = std::abs(errors.amplitude);
  if (ref.solution) {
    cell->max_error = errors.max_error;
    cell->error = errors.max_error;
  } else if (ref.has_amplitude()) {
    cell->error = cell->amplitude_error;
  } else if (ref.has_frequency()) {
    cell->error = cell->frequency_error;
  } else if (source.original || source.original_dae) {
    const double period = 2 * M_PI / *std::min_element(sol.frequencies().begin(), sol.frequencies().end());
    const integrators::ValidationReport v = ValidateOriginal(source, sol, period, 2001, state);
    cell->trajectory_error = v.ok ? v.max_error : kNaN;
    cell->error = cell->trajectory_error;
  }
}

Cell Run(const ProblemSource& source, const Column& column, int order, int repeat) {
  Cell cell;
  std::optional<HarmonicBalanceSummary> best;
  try {
    for (int r = 0; r < repeat; ++r) {
      HarmonicBalanceSummary s = column.solve(order);
      if (!best || s.seconds < best->seconds) best = std::move(s);
    }
  } catch (const std::invalid_argument& e) {  // e.g. a grid refused up front
    cell.status = "refused";
    cell.message = e.what();
    return cell;
  }
  const HarmonicBalanceSummary& s = *best;
  cell.status = s.converged() ? "converged" : ToString(s.solver.status);
  cell.message = s.solver.message;
  cell.samples = s.samples.empty() ? 0 : s.samples[0];
  cell.iterations = s.solver.iterations;
  if (s.solver.reciprocal_condition > 0) cell.reciprocal_condition = s.solver.reciprocal_condition;
  cell.residual = s.solver.final_residual;
  cell.seconds = s.seconds;
  if (s.converged()) Measure(source, *s.solution, column.state, &cell);
  cell.physical = s.physical;
  cell.non_physical = s.non_physical;
  if (s.definition_check) cell.definition_error = s.definition_check->error;
  return cell;
}

json CellJson(int order, const Cell& c) {
  return {{"order", order}, {"status", c.status}, {"message", c.message}, {"samples", c.samples},
          {"iterations", c.iterations}, {"residual", Number(c.residual)}, {"seconds", Number(c.seconds)},
          {"reciprocal_condition", Number(c.reciprocal_condition)},
          {"error", Number(c.error)}, {"frequency_error", Number(c.frequency_error)},
          {"amplitude_error", Number(c.amplitude_error)}, {"max_error", Number(c.max_error)},
          {"trajectory_error", Number(c.trajectory_error)}, {"physical", c.physical},
          {"non_physical", c.non_physical}, {"definition_error", Number(c.definition_error)}};
}

std::string CellText(const Cell& c) {
  char buf[64];
  if (c.status == "converged" && !c.physical)  // '!': see the note under the table
    std::snprintf(buf, sizeof buf, "%7.1e! %8.2f %5d", c.error, c.seconds * 1e3, c.samples);
  else if (c.status == "converged" && std::isfinite(c.error))
    std::snprintf(buf, sizeof buf, "%8.1e %8.2f %5d", c.error, c.seconds * 1e3, c.samples);
  else if (c.status == "converged")
    std::snprintf(buf, sizeof buf, "%8s %8.2f %5d", "n/a", c.seconds * 1e3, c.samples);
  else if (std::isfinite(c.residual))
    std::snprintf(buf, sizeof buf, "fails |F| %7.1e %5d", c.residual, c.samples);
  else
    std::snprintf(buf, sizeof buf, "%-23s", c.status.substr(0, 23).c_str());
  return buf;
}

// RHB-Taylor's system: the model's equations Taylor-expanded, recast.
// Null with the reason in *error when there is none.
std::shared_ptr<model::RecastResult> TaylorRecast(const ProblemSource& source, int order, std::string* error) {
  std::shared_ptr<const model::ModelDefinition> definition = source.definition;
  if (!definition) {
    const std::string file = TwinModelFile(source.name);
    if (!file.empty()) definition = std::make_shared<const model::ModelDefinition>(model::LoadModelFile(file));
  }
  if (!definition) {
    *error = "needs the model's equations: pass a model file (examples/models/" + source.name + ".yaml)";
  } else if (source.problem.frequencies.size() != 1) {
    *error = "periodic models only";
  } else {
    try {
      return std::make_shared<model::RecastResult>(
          model::Recast(model::TaylorExpanded(*definition, order), source.overrides));
    } catch (const model::ModelError& e) {
      *error = e.what();
    }
  }
  return nullptr;
}

// The original equations as an explicit ODE with the user's conditions
// moved onto its states. Null with the reason in *error when there is none.
std::shared_ptr<ExplicitOdeProblem> OriginalOde(const ProblemSource& source, std::string* error) {
  if (!source.original) {
    *error = source.original_error;
    return nullptr;
  }
  if (source.problem.frequencies.size() != 1) {
    *error = "periodic models only";
    return nullptr;
  }
  auto ode = std::make_shared<ExplicitOdeProblem>();
  ode->names = source.state_names;
  ode->rhs = source.original(source.problem.frequencies).rhs;
  ode->frequency = source.problem.frequencies[0];
  ode->unknown_frequency = !source.problem.unknown_frequency.empty() && source.problem.unknown_frequency[0];
  for (int c = 0; c < source.num_user_conditions; ++c)
    ode->conditions.push_back(
        OnStates(source.problem.conditions[c], source.state_sources, source.problem.system.num_variables()));
  return ode;
}

// Error against run time (log-log) and against order, one line per column.
void PlotTable(const ProblemSource& source, const std::string& measure, const std::vector<int>& orders,
               const std::vector<Column>& columns, const std::string& file) {
  Plot plot{source.name + ": " + source.equation, {}};
  PlotPanel speed{"error against run time", "run time [s]", "error: " + measure, true, true, {}};
  PlotPanel order{"error against order", source.problem.frequencies.size() == 1 ? "order N" : "order p", "error",
                  false, true, {}};
  for (const auto& col : columns) {
    PlotSeries s{col.name, {}, {}, PlotSeries::Style::kLinesPoints, {}}, o = s;
    for (size_t i = 0; i < orders.size(); ++i) {
      if (col.cells[i].status != "converged") continue;
      s.x.push_back(col.cells[i].seconds), s.y.push_back(col.cells[i].error);
      o.x.push_back(orders[i]), o.y.push_back(col.cells[i].error);
    }
    speed.series.push_back(s);
    order.series.push_back(o);
  }
  plot.panels = {speed, order};
  WritePlot(plot, file);
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

int RunConvergence(const ConvergenceArgs& a) {
  const std::vector<int> orders = ParseOrders(a.orders);
  if (!a.plot.empty()) CheckPlotRequest(a.plot);
  SolveSettings settings = a.settings;
  settings.order = orders[0];
  PreparedSolve prepared = PrepareSolve(settings);
  const ProblemSource& source = prepared.source;
  const HarmonicBalanceOptions base_options = prepared.options;
  HarmonicBalanceOptions highest = base_options;
  highest.order = *std::max_element(orders.begin(), orders.end());
  CheckJacobianSize(source.problem, highest);
  const bool periodic = source.problem.frequencies.size() == 1;
  bool auxiliaries = false;
  for (const auto& v : source.problem.system.variables()) auxiliaries |= v.role == VariableRole::kAuxiliary;

  std::vector<std::string> methods = SplitList(a.methods);
  if (methods.empty()) {
    methods = {"rhb", "hdhb", "aft"};
    if (auxiliaries && periodic) methods.insert(methods.end(), {"taylor", "original"});
  }
  std::vector<std::string> solvers = SplitList(a.solvers);
  if (solvers.empty()) solvers = {"auto"};
  const std::vector<std::string> schemes = SplitList(a.conditions);
  if (schemes.empty()) throw std::invalid_argument("--conditions: empty list");
  for (const auto& m : methods)
    if (m != "rhb" && m != "hdhb" && m != "aft" && m != "taylor" && m != "original")
      throw std::invalid_argument("--methods: unknown method '" + m + "' (rhb, hdhb, aft, taylor, original)");
  for (const auto& s : solvers) ParseSolverMethod(s);  // throws naming it
  for (const auto& c : schemes)
    if (c != "model" && c != "scheme1" && c != "scheme2" && c != "scheme3")
      throw std::invalid_argument("--conditions: unknown scheme '" + c + "' (model, scheme1, scheme2, scheme3)");

  // Shared by the columns: the condition variants, the Taylor recast, the
  // original equations as an explicit ODE.
  std::vector<std::shared_ptr<HarmonicBalanceProblem>> problems;
  for (const auto& c : schemes) problems.push_back(std::make_shared<HarmonicBalanceProblem>(WithConditions(source, c)));
  const HarmonicBalanceProblem& default_problem = source.problem;
  auto guess_at = [&source](int order) { return GuessAtOrder(source, order); };

  std::string taylor_error, ode_error;
  std::shared_ptr<model::RecastResult> taylor;
  if (std::count(methods.begin(), methods.end(), "taylor")) taylor = TaylorRecast(source, a.taylor_order, &taylor_error);
  std::shared_ptr<ExplicitOdeProblem> ode;
  if (std::count(methods.begin(), methods.end(), "original")) ode = OriginalOde(source, &ode_error);

  std::vector<Column> columns;
  for (size_t ci = 0; ci < schemes.size(); ++ci)
    for (const auto& solver : solvers)
      for (const auto& method : methods) {
        const bool recast_method = method == "rhb" || method == "hdhb" || method == "aft";
        if (!recast_method && schemes[ci] != "model") continue;  // schemes are about the recast's conditions
        Column col;
        col.method = method;
        col.solver = solver;
        col.conditions = schemes[ci];
        col.name = method;
        if (solvers.size() > 1) col.name += "/" + solver;
        if (schemes.size() > 1) col.name += "/" + schemes[ci];
        HarmonicBalanceOptions options = base_options;
        options.solver.method = ParseSolverMethod(solver);
        options.solver.max_seconds = a.max_seconds;
        col.state = source.state;
        if (recast_method) {
          options.rule = ParseSamplingRule(method);
          options.samples.clear();
          auto problem = problems[ci];
          col.solve = [problem, options, guess_at](int order) {
            HarmonicBalanceOptions o = options;
            o.order = order;
            return SolveHarmonicBalance(*problem, guess_at(order), o);
          };
        } else if (method == "taylor") {
          if (!taylor) {
            col.unavailable = taylor_error;
          } else {
            options.rule = SamplingRule::kRhb;
            options.samples.clear();
            options.basis_for_order = nullptr;
            col.solve = [taylor, options](int order) {
              HarmonicBalanceOptions o = options;
              o.order = order;
              return SolveHarmonicBalance(taylor->problem, taylor->InitialGuess(order), o);
            };
            if (taylor->original) col.state = [taylor](const HarmonicSolution& s, double t) {
              const std::vector<double> v = taylor->original->StateFromSolution(s, t);
              return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(v.size())).eval();
            };
          }
        } else {  // original
          if (!ode) {
            col.unavailable = ode_error;
          } else {
            PointwiseCollocationOptions po;
            po.solver = options.solver;
            const PolynomialSystem& system = default_problem.system;
            const int fixed_samples = a.original_samples;
            col.solve = [ode, po, guess_at, &source, &system, fixed_samples](int order) {
              PointwiseCollocationOptions o = po;
              o.order = order;
              // By default the HB-AFT count of the recast system at this order (a power of two).
              o.samples = fixed_samples > 0 ? fixed_samples
                                            : SamplesForRule(system, HarmonicBasis::Periodic(order), SamplingRule::kAft)[0];
              const HarmonicSolution recast_guess = guess_at(order);
              const double w = recast_guess.frequencies()[0];
              std::vector<Variable> states;
              for (const auto& n : ode->names) states.push_back({n, VariableRole::kState, ""});
              const HarmonicSolution g = HarmonicSolution::FromAngles(
                  HarmonicBasis::Periodic(order), {w}, states,
                  [&](const std::vector<double>& th) { return source.state(recast_guess, th[0] / w); });
              return SolvePointwiseCollocation(*ode, g, o);
            };
            col.state = [](const HarmonicSolution& s, double t) {
              Eigen::VectorXd y(s.num_variables());
              for (int j = 0; j < s.num_variables(); ++j) y(j) = s.Value(j, t);
              return y;
            };
          }
        }
        columns.push_back(std::move(col));
      }

  int converged = 0, physical = 0;
  for (auto& col : columns)
    for (int order : orders) {
      col.cells.push_back(col.unavailable.empty() ? Run(source, col, order, a.repeat) : Cell{});
      converged += col.cells.back().status == "converged";
      physical += col.cells.back().status == "converged" && col.cells.back().physical;
    }

  const std::string first = source.problem.system.variables()[0].name;
  const std::string measure = ErrorMeasure(source, first);
  if (!a.plot.empty()) PlotTable(source, measure, orders, columns, a.plot);

  if (a.json) {
    json cols = json::array();
    for (const auto& col : columns) {
      json rows = json::array();
      for (size_t i = 0; i < col.cells.size(); ++i) rows.push_back(CellJson(orders[i], col.cells[i]));
      cols.push_back({{"name", col.name}, {"method", col.method}, {"solver", col.solver},
                      {"conditions", col.conditions}, {"unavailable", col.unavailable}, {"rows", rows}});
    }
    json out{{"model", a.settings.model}, {"equation", source.equation}, {"error_measure", measure},
             {"reference", source.reference.source.empty() ? "CVODE trajectory" : source.reference.source},
             {"orders", orders}, {"degree", source.problem.system.Degree()}, {"columns", cols}};
    if (taylor) out["taylor"] = {{"order", a.taylor_order}, {"degree", taylor->degree}};
    if (!a.plot.empty()) out["plot"] = a.plot;
    std::cout << out.dump(1) << "\n";
  } else {
    std::printf("%s: %s  (recast degree phi = %d)\n", source.name.c_str(), source.equation.c_str(),
                source.problem.system.Degree());
    std::printf("error: %s%s%s\n", measure.c_str(), source.reference.source.empty() ? "" : "; ",
                source.reference.source.c_str());
    std::printf("cells: error, run time [ms], samples M\n\n%5s", periodic ? "N" : "p");
    for (const auto& col : columns) std::printf(" | %-23s", col.name.c_str());
    std::printf("\n");
    for (size_t i = 0; i < orders.size(); ++i) {
      std::printf("%5d", orders[i]);
      for (const auto& col : columns) std::printf(" | %s", CellText(col.cells[i]).c_str());
      std::printf("\n");
    }
    for (const auto& col : columns) {
      if (!col.unavailable.empty()) std::printf("%s: not run: %s\n", col.name.c_str(), col.unavailable.c_str());
      for (size_t i = 0; i < col.cells.size(); ++i)
        if (col.cells[i].status == "converged" && !col.cells[i].physical)
          std::printf("%s, order %d: ! NON-PHYSICAL: %s\n", col.name.c_str(), orders[i],
                      col.cells[i].non_physical.c_str());
      for (size_t i = 0; i < col.cells.size(); ++i)
        if (col.cells[i].status == "refused") {
          std::printf("%s, order %d: refused: %s\n", col.name.c_str(), orders[i], col.cells[i].message.c_str());
          break;
        }
    }
    if (taylor) std::printf("taylor: the non-polynomial terms replaced by their Taylor polynomials of order %d (phi = %d)\n",
                            a.taylor_order, taylor->degree);
    if (std::count(methods.begin(), methods.end(), "original"))
      std::printf("original: HB-AFT on the original right-hand side, M = %s (aliases)\n",
                  a.original_samples > 0 ? std::to_string(a.original_samples).c_str() : "the recast's AFT count");
  }
  if (converged == 0) {
    std::fprintf(stderr, "rmhb: no solve converged\n");
    return kExitNotConverged;
  }
  if (physical == 0) {
    std::fprintf(stderr, "rmhb: every converged solve is NON-PHYSICAL\n");
    return kExitNonPhysical;
  }
  return kExitOk;
}

}  // namespace rmhb::cli
