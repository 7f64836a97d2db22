#include "rmhb/pipeline/convergence.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "rmhb/model/recast.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/model/taylor_expansion.h"
#include "rmhb/pointwise_collocation.h"

namespace rmhb {
namespace {

using SolveAt = std::function<HarmonicBalanceSummary(int order)>;

// A column while it runs: how to solve at an order, and how to read the
// original state off its solutions.
struct Column {
  ConvergenceColumn column;
  SolveAt solve;
  StateOfSolution state;
};

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

// Which error the table shows: the strongest the reference allows.
std::string ErrorMeasure(const Model& source, const std::string& first_variable) {
  const ExactReference& ref = source.reference;
  if (ref.solution) return "max over one period of |" + first_variable + "(t) - exact|";
  if (ref.has_amplitude()) return "|amplitude of " + ref.amplitude_variable + " - exact|";
  if (ref.has_frequency()) return "|w - exact|";
  return std::string("max state error over one period against ") +
         (source.original_dae ? "IDA (BDF, rtol 1e-14)" : source.stiff ? "CVODE (BDF, rtol 1e-12)" : "CVODE (Adams, rtol 1e-13)") +
         " started on the solution";
}

void Measure(const Model& source, const HarmonicSolution& sol, const StateOfSolution& state, ConvergenceCell* cell) {
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
    cell->trajectory_error = v.ok ? v.max_error : ConvergenceCell::kNaN;
    cell->error = cell->trajectory_error;
  }
}

ConvergenceCell Run(const Model& source, const Column& column, int order, int repeat) {
  ConvergenceCell cell;
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

// RHB-Taylor's system: the model's equations Taylor-expanded, recast.
// Null with the reason in *error when there is none.
std::shared_ptr<model::RecastResult> TaylorRecast(const Model& source, int order, std::string* error) {
  const std::shared_ptr<const model::ModelDefinition>& definition = source.definition;
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
std::shared_ptr<ExplicitOdeProblem> OriginalOde(const Model& source, std::string* error) {
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

// One column's solver at every order. Columns other than the recast's
// (taylor, original) use the model's conditions only.
Column MakeColumn(const Model& source, StudyMethod method, SolverMethod solver, ConstraintScheme scheme,
                  const std::shared_ptr<HarmonicBalanceProblem>& problem,
                  const std::shared_ptr<model::RecastResult>& taylor, const std::string& taylor_error,
                  const std::shared_ptr<ExplicitOdeProblem>& ode, const std::string& ode_error,
                  const ConvergenceOptions& o) {
  Column col;
  col.column.method = method;
  col.column.solver = solver;
  col.column.scheme = scheme;
  HarmonicBalanceOptions options = o.solve;
  options.solver.method = solver;
  col.state = source.state;
  auto guess_at = [&source](int order) { return GuessAtOrder(source, order); };
  if (method == StudyMethod::kRhb || method == StudyMethod::kHdhb || method == StudyMethod::kAft) {
    options.rule = ParseSamplingRule(ToString(method));
    options.samples.clear();
    col.solve = [problem, options, guess_at](int order) {
      HarmonicBalanceOptions h = options;
      h.order = order;
      return SolveHarmonicBalance(*problem, guess_at(order), h);
    };
  } else if (method == StudyMethod::kTaylor) {
    if (!taylor) {
      col.column.unavailable = taylor_error;
      return col;
    }
    options.rule = SamplingRule::kRhb;
    options.samples.clear();
    options.basis_for_order = nullptr;
    col.solve = [taylor, options](int order) {
      HarmonicBalanceOptions h = options;
      h.order = order;
      return SolveHarmonicBalance(taylor->problem, taylor->InitialGuess(order), h);
    };
    if (taylor->original) col.state = [taylor](const HarmonicSolution& s, double t) {
      const std::vector<double> v = taylor->original->StateFromSolution(s, t);
      return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(v.size())).eval();
    };
  } else {  // original
    if (!ode) {
      col.column.unavailable = ode_error;
      return col;
    }
    PointwiseCollocationOptions po;
    po.solver = options.solver;
    const int fixed_samples = o.original_samples;
    col.solve = [ode, po, guess_at, &source, fixed_samples](int order) {
      PointwiseCollocationOptions p = po;
      p.order = order;
      // By default the HB-AFT count of the recast system at this order (a power of two).
      p.samples = fixed_samples > 0 ? fixed_samples
                                    : SamplesForRule(source.problem.system, HarmonicBasis::Periodic(order),
                                                     SamplingRule::kAft)[0];
      const HarmonicSolution recast_guess = guess_at(order);
      const double w = recast_guess.frequencies()[0];
      std::vector<Variable> states;
      for (const auto& n : ode->names) states.push_back({n, VariableRole::kState, ""});
      const HarmonicSolution g = HarmonicSolution::FromAngles(
          HarmonicBasis::Periodic(order), {w}, states,
          [&](const std::vector<double>& th) { return source.state(recast_guess, th[0] / w); });
      return SolvePointwiseCollocation(*ode, g, p);
    };
    col.state = [](const HarmonicSolution& s, double t) {
      Eigen::VectorXd y(s.num_variables());
      for (int j = 0; j < s.num_variables(); ++j) y(j) = s.Value(j, t);
      return y;
    };
  }
  return col;
}

std::vector<StudyMethod> DefaultMethods(const Model& model) {
  bool auxiliaries = false;
  for (const auto& v : model.problem.system.variables()) auxiliaries |= v.role == VariableRole::kAuxiliary;
  std::vector<StudyMethod> methods = {StudyMethod::kRhb, StudyMethod::kHdhb, StudyMethod::kAft};
  if (auxiliaries && model.problem.frequencies.size() == 1)
    methods.insert(methods.end(), {StudyMethod::kTaylor, StudyMethod::kOriginal});
  return methods;
}

}  // namespace

const char* ToString(ConstraintScheme scheme) {
  switch (scheme) {
    case ConstraintScheme::kModel: return "model";
    case ConstraintScheme::kScheme1: return "scheme1";
    case ConstraintScheme::kScheme2: return "scheme2";
    case ConstraintScheme::kScheme3: return "scheme3";
  }
  return "model";
}

ConstraintScheme ParseConstraintScheme(const std::string& name) {
  for (ConstraintScheme s : {ConstraintScheme::kModel, ConstraintScheme::kScheme1, ConstraintScheme::kScheme2,
                             ConstraintScheme::kScheme3})
    if (name == ToString(s)) return s;
  throw std::invalid_argument("--conditions: unknown scheme '" + name + "' (model, scheme1, scheme2, scheme3)");
}

const char* ToString(StudyMethod method) {
  switch (method) {
    case StudyMethod::kRhb: return "rhb";
    case StudyMethod::kHdhb: return "hdhb";
    case StudyMethod::kAft: return "aft";
    case StudyMethod::kTaylor: return "taylor";
    case StudyMethod::kOriginal: return "original";
  }
  return "rhb";
}

StudyMethod ParseStudyMethod(const std::string& name) {
  for (StudyMethod m : {StudyMethod::kRhb, StudyMethod::kHdhb, StudyMethod::kAft, StudyMethod::kTaylor,
                        StudyMethod::kOriginal})
    if (name == ToString(m)) return m;
  throw std::invalid_argument("--methods: unknown method '" + name + "' (rhb, hdhb, aft, taylor, original)");
}

HarmonicBalanceProblem WithConstraintScheme(const Model& source, ConstraintScheme scheme) {
  HarmonicBalanceProblem p = source.problem;
  if (scheme == ConstraintScheme::kModel) return p;
  const int users = source.num_user_conditions;
  if (users < (scheme == ConstraintScheme::kScheme3 ? 2 : 1))
    throw std::invalid_argument(std::string("--conditions ") + ToString(scheme) + ": the model has " +
                                std::to_string(users) +
                                " condition(s) of its own; the schemes need amplitude and phase conditions");
  const std::vector<PointCondition> all = source.problem.conditions;
  std::vector<PointCondition> pins(all.begin() + users, all.end());
  if (scheme == ConstraintScheme::kScheme1) {
    PolynomialSystem balanced;
    for (const auto& v : p.system.variables()) balanced.AddVariable(v.name, v.role, v.definition);
    for (const auto& e : p.system.equations()) balanced.AddEquation(e.lhs, true);
    p.system = balanced;
    p.conditions = {all[0]};
  } else {
    p.conditions = {all[scheme == ConstraintScheme::kScheme2 ? 0 : 1]};
    p.conditions.insert(p.conditions.end(), pins.begin(), pins.end());
  }
  return p;
}

std::string ConvergenceOptions::IsValid() const {
  if (orders.empty()) return "no orders";
  for (int n : orders)
    if (n < 1) return "orders must be >= 1";
  if (solvers.empty() || schemes.empty()) return "no solver or no constraint scheme";
  if (repeat < 1) return "repeat must be >= 1";
  if (taylor_order < 1) return "taylor_order must be >= 1";
  if (original_samples < 0) return "original_samples must be >= 0";
  return "";
}

ConvergenceSummary ConvergenceStudy(const Model& source, const ConvergenceOptions& options) {
  if (const std::string error = options.IsValid(); !error.empty())
    throw std::invalid_argument("convergence study: " + error);
  HarmonicBalanceOptions highest = options.solve;
  highest.order = *std::max_element(options.orders.begin(), options.orders.end());
  CheckJacobianSize(source.problem, highest);
  const std::vector<StudyMethod> methods = options.methods.empty() ? DefaultMethods(source) : options.methods;
  auto uses = [&](StudyMethod m) { return std::count(methods.begin(), methods.end(), m) > 0; };

  // Shared by the columns: the condition variants, the Taylor recast, the
  // original equations as an explicit ODE.
  std::vector<std::shared_ptr<HarmonicBalanceProblem>> problems;
  for (ConstraintScheme c : options.schemes)
    problems.push_back(std::make_shared<HarmonicBalanceProblem>(WithConstraintScheme(source, c)));
  std::string taylor_error, ode_error;
  std::shared_ptr<model::RecastResult> taylor;
  if (uses(StudyMethod::kTaylor)) taylor = TaylorRecast(source, options.taylor_order, &taylor_error);
  std::shared_ptr<ExplicitOdeProblem> ode;
  if (uses(StudyMethod::kOriginal)) ode = OriginalOde(source, &ode_error);

  ConvergenceSummary summary;
  summary.orders = options.orders;
  if (taylor) summary.taylor_degree = taylor->degree;
  for (size_t ci = 0; ci < options.schemes.size(); ++ci)
    for (SolverMethod solver : options.solvers)
      for (StudyMethod method : methods) {
        const bool recast_method = method == StudyMethod::kRhb || method == StudyMethod::kHdhb ||
                                   method == StudyMethod::kAft;
        // The schemes are about the recast's conditions.
        if (!recast_method && options.schemes[ci] != ConstraintScheme::kModel) continue;
        Column col = MakeColumn(source, method, solver, options.schemes[ci], problems[ci], taylor, taylor_error,
                                ode, ode_error, options);
        col.column.name = ToString(method);
        if (options.solvers.size() > 1) col.column.name += std::string("/") + ToString(solver);
        if (options.schemes.size() > 1) col.column.name += std::string("/") + ToString(options.schemes[ci]);
        for (int order : options.orders) {
          col.column.cells.push_back(col.column.unavailable.empty() ? Run(source, col, order, options.repeat)
                                                                    : ConvergenceCell{});
          summary.converged += col.column.cells.back().converged();
          summary.physical += col.column.cells.back().converged() && col.column.cells.back().physical;
        }
        summary.columns.push_back(std::move(col.column));
      }
  summary.error_measure = ErrorMeasure(source, source.problem.system.variables()[0].name);
  summary.model_name = source.name;
  summary.equation = source.equation;
  summary.reference_source = source.reference.source;
  summary.degree = source.problem.system.Degree();
  summary.bases = static_cast<int>(source.problem.frequencies.size());
  summary.taylor_order = options.taylor_order;
  summary.original_samples = options.original_samples;
  summary.original_listed = std::count(options.methods.begin(), options.methods.end(), StudyMethod::kOriginal) > 0;
  for (const auto& col : summary.columns) summary.original_listed |= col.method == StudyMethod::kOriginal;
  return summary;
}

std::string ConvergenceSummary::BriefReport() const {
  std::ostringstream out;
  out << "convergence study: " << columns.size() << " columns x " << orders.size() << " orders, " << converged
      << " converged (" << physical << " physical); error: " << error_measure << "\n";
  return out.str();
}

namespace {

using nlohmann::json;

json CellJson(int order, const ConvergenceCell& c) {
  return {{"order", order}, {"status", c.status}, {"message", c.message}, {"samples", c.samples},
          {"iterations", c.iterations}, {"residual", JsonNumber(c.residual)}, {"seconds", JsonNumber(c.seconds)},
          {"reciprocal_condition", JsonNumber(c.reciprocal_condition)},
          {"error", JsonNumber(c.error)}, {"frequency_error", JsonNumber(c.frequency_error)},
          {"amplitude_error", JsonNumber(c.amplitude_error)}, {"max_error", JsonNumber(c.max_error)},
          {"trajectory_error", JsonNumber(c.trajectory_error)}, {"physical", c.physical},
          {"non_physical", c.non_physical}, {"definition_error", JsonNumber(c.definition_error)}};
}

std::string CellText(const ConvergenceCell& c) {
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

// What the table leaves out: columns not run, non-physical and refused cells.
std::string ColumnNotes(const ConvergenceSummary& study) {
  std::string out;
  for (const auto& col : study.columns) {
    if (!col.unavailable.empty()) out += col.name + ": not run: " + col.unavailable + "\n";
    for (size_t i = 0; i < col.cells.size(); ++i)
      if (col.cells[i].converged() && !col.cells[i].physical)
        out += StringPrintf("%s, order %d: ! NON-PHYSICAL: %s\n", col.name.c_str(), study.orders[i],
                      col.cells[i].non_physical.c_str());
    for (size_t i = 0; i < col.cells.size(); ++i)
      if (col.cells[i].status == "refused") {
        out += StringPrintf("%s, order %d: refused: %s\n", col.name.c_str(), study.orders[i], col.cells[i].message.c_str());
        break;
      }
  }
  return out;
}

}  // namespace

std::string ConvergenceSummary::FullReport() const {
  std::string out = StringPrintf("%s: %s  (recast degree phi = %d)\n", model_name.c_str(), equation.c_str(), degree);
  out += "error: " + error_measure + (reference_source.empty() ? "" : "; ") + reference_source + "\n";
  out += StringPrintf("cells: error, run time [ms], samples M\n\n%5s", bases == 1 ? "N" : "p");
  for (const auto& col : columns) out += StringPrintf(" | %-23s", col.name.c_str());
  out += "\n";
  for (size_t i = 0; i < orders.size(); ++i) {
    out += StringPrintf("%5d", orders[i]);
    for (const auto& col : columns) out += " | " + CellText(col.cells[i]);
    out += "\n";
  }
  out += ColumnNotes(*this);
  if (taylor_degree >= 0)
    out += StringPrintf("taylor: the non-polynomial terms replaced by their Taylor polynomials of order %d (phi = %d)\n",
                  taylor_order, taylor_degree);
  if (original_listed)
    out += "original: HB-AFT on the original right-hand side, M = " +
           (original_samples > 0 ? std::to_string(original_samples) : std::string("the recast's AFT count")) +
           " (aliases)\n";
  return out;
}

json ConvergenceSummary::ToJson() const {
  json cols = json::array();
  for (const auto& col : columns) {
    json rows = json::array();
    for (size_t i = 0; i < col.cells.size(); ++i) rows.push_back(CellJson(orders[i], col.cells[i]));
    cols.push_back({{"name", col.name}, {"method", ToString(col.method)}, {"solver", ToString(col.solver)},
                    {"conditions", ToString(col.scheme)}, {"unavailable", col.unavailable}, {"rows", rows}});
  }
  json out{{"equation", equation}, {"error_measure", error_measure},
           {"reference", reference_source.empty() ? "CVODE trajectory" : reference_source},
           {"orders", orders}, {"degree", degree}, {"columns", cols}};
  if (taylor_degree >= 0) out["taylor"] = {{"order", taylor_order}, {"degree", taylor_degree}};
  return out;
}

}  // namespace rmhb
