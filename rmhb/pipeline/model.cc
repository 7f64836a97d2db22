#include "rmhb/pipeline/model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "frequency_id/spectrum.h"
#include "frequency_id/window.h"
#include "integrators/cvode_integrator.h"
#include "integrators/event_detection.h"
#include "integrators/ida_integrator.h"
#include "integrators/variational.h"
#include "rmhb/model/recast.h"
#include "rmhb/pipeline/settings.h"

namespace rmhb {

const char* ToString(EquationsRoute route) {
  switch (route) {
    case EquationsRoute::kRecast: return "recast";
    case EquationsRoute::kOriginal: return "original";
    case EquationsRoute::kAuto: return "auto";
  }
  return "?";
}

EquationsRoute ParseEquationsRoute(const std::string& name) {
  if (name == "recast") return EquationsRoute::kRecast;
  if (name == "original") return EquationsRoute::kOriginal;
  if (name == "auto") return EquationsRoute::kAuto;
  throw std::invalid_argument("unknown equations '" + name + "' (expected recast, original or auto)");
}

namespace {

// The model on its original equations: the problem, and the guess and the
// seeding map cut to the user variables and their chains (the recast's
// first variables, in the same order).
void UseOriginalEquations(const std::shared_ptr<model::RecastResult>& recast, Model* p) {
  const int n = recast->original_problem->system.num_variables();
  p->problem = *recast->original_problem;
  p->guess = [recast, n](int order) {
    const HarmonicSolution full = recast->InitialGuess(order);
    const std::vector<Variable>& all = full.variables();
    return HarmonicSolution(full.basis(), full.frequencies(), full.coefficients().topRows(n),
                            std::vector<Variable>(all.begin(), all.begin() + n));
  };
  if (p->variables) {
    const seeding::StateToVariables full = p->variables;
    p->variables = [full, n](const std::vector<double>& theta, const std::vector<Eigen::VectorXd>& y) {
      return Eigen::VectorXd(full(theta, y).head(n));
    };
  }
  if (recast->original_half_wave) p->invariances = {*recast->original_half_wave};
  p->recast_report = "original equations, evaluated pointwise (HB-AFT; no alias-free sample count):\n" +
                     p->problem.system.ToString();
  p->equations = "original";
}

bool HasAuxiliaries(const HarmonicBalanceProblem& problem) {
  for (const Variable& v : problem.system.variables())
    if (v.role == VariableRole::kAuxiliary) return true;
  return false;
}

void ChooseEquations(const std::shared_ptr<model::RecastResult>& recast, EquationsRoute route, Model* p) {
  if (route == EquationsRoute::kRecast) return;
  if (!recast->original_problem) {
    if (route == EquationsRoute::kOriginal)
      throw std::invalid_argument("the original equations cannot be solved as written: " +
                                  recast->original_problem_error);
    p->equations_note = "recast: " + recast->original_problem_error;
    return;
  }
  if (route == EquationsRoute::kAuto && !HasAuxiliaries(recast->problem)) {
    p->equations_note = "recast: polynomial, alias-free at the same size";
    return;
  }
  UseOriginalEquations(recast, p);
  if (route == EquationsRoute::kAuto)
    p->equations_note = "original: the recast needs " +
                        std::to_string(recast->problem.system.num_variables() - p->problem.system.num_variables()) +
                        " auxiliaries";
}

// Default conditions (rmhb/METHOD.md s.20): an autonomous model whose one
// base frequency is unknown and which gives no conditions needs a phase
// condition, and a conservative one also an amplitude: its orbits form a
// family. The trajectory from initial_state tells them apart: if it returns
// to initial_state (closest return on the section through it, normal to the
// flow, within kClosedOrbit), initial_state is on a periodic orbit and the
// conditions are initial_state itself (the bundled conservative examples'
// choice; least squares); otherwise the motion approaches an orbit (or is not
// periodic) and only the phase is fixed, by the first variable's turning
// point x'(0) = 0.
constexpr double kClosedOrbit = 1e-7;  // relative to max(1, |y0|_inf)

bool NeedsDefaultConditions(const model::ModelDefinition& definition, const Model& p) {
  return definition.conditions.empty() && p.problem.frequencies.size() == 1 && p.original &&
         !p.problem.unknown_frequency.empty() && p.problem.unknown_frequency[0];
}

// min |y(t_k) - y0|_inf / max(1, |y0|_inf) over the returns t_k to the
// section through y0 in 10 guessed periods; infinity when there are none.
double ClosestReturn(const Model& p) {
  const Eigen::VectorXd& y0 = p.initial_state;
  integrators::IntegratorOptions io;
  io.method = integrators::IntegratorOptions::Method::kBdf;  // stiff or not
  io.relative_tolerance = 1e-12;
  io.absolute_tolerance = 1e-14;
  integrators::IntegrationResult info;
  integrators::SectionReturns(p.original(p.problem.frequencies), y0, 10 * 2 * M_PI / p.problem.frequencies[0], io,
                              &info);
  double closest = HUGE_VAL;
  const Eigen::MatrixXd& states = info.trajectory.states;
  for (long k = 0; k < states.rows(); ++k)
    closest = std::min(closest, (states.row(k).transpose() - y0).lpNorm<Eigen::Infinity>());
  return closest / std::max(1.0, y0.lpNorm<Eigen::Infinity>());
}

// "x(0) = (initial_state's text)" for every state: expressions of the
// parameters, so a reload at other values follows them.
std::vector<std::string> OrbitThroughInitialState(const model::ModelDefinition& definition, const Model& p) {
  std::vector<std::string> out;
  for (long i = 0; i < p.initial_state.size(); ++i) {
    char number[32];
    std::snprintf(number, sizeof number, "%.17g", p.initial_state(i));
    std::string value = number;
    for (const auto& [key, text] : definition.initial_state)
      if (key == p.state_names[i]) value = "(" + text.text + ")";
    out.push_back(p.state_names[i] + "(0) = " + value);  // state names are x, x', x'', ...
  }
  return out;
}

std::vector<std::string> DefaultConditions(const model::ModelDefinition& definition, const Model& p,
                                           std::string* note) {
  const std::vector<std::string> phase = {definition.variables[0] + "'(0) = 0"};
  if (definition.initial_state.empty()) {
    *note = "default: the phase only; without initial_state nothing tells a conservative family from a limit "
            "cycle, nor seeds the solve";
    return phase;
  }
  const double closest = ClosestReturn(p);
  char number[32], bound[16];
  std::snprintf(number, sizeof number, "%.2g", closest);
  std::snprintf(bound, sizeof bound, "%.0e", kClosedOrbit);
  if (closest <= kClosedOrbit) {
    *note = std::string("default: the orbit through initial_state, which the trajectory returns to within ") +
            number + " (relative, <= " + bound + "): a family of orbits, amplitude and phase fixed";
    return OrbitThroughInitialState(definition, p);
  }
  *note = "default: the phase only, the trajectory from initial_state " +
          (std::isfinite(closest) ? "returning no closer than " + std::string(number) + " to it (relative, > " + bound + ")"
                                  : std::string("not returning to it")) +
          ": no periodic orbit through it (one the motion approaches, or none)";
  return phase;  // every variable of an ODE model is differential: the first has x'.
}

// 2 pi / |J|_inf, J = df/dy at y0 by differences: the time scale of the
// flow there, from which the search for a period starts. Refuses an
// equilibrium and a flow without a time scale (J zero or not finite).
double FlowTimeScale(const integrators::OdeSystem& ode, const Eigen::VectorXd& y0, const model::SourceLocation& at) {
  Eigen::VectorXd f0(y0.size());
  ode.rhs(0, y0.data(), f0.data());
  const Eigen::MatrixXd J = integrators::DifferenceJacobian(ode, 0, y0.data());
  const double rate = J.allFinite() ? J.cwiseAbs().rowwise().sum().maxCoeff() : 0;
  const bool rest = f0.allFinite() && f0.lpNorm<Eigen::Infinity>() == 0;
  if (rest || !f0.allFinite() || !(rate > 0))
    throw model::ModelError(std::string("no 'frequencies', and ") +
                                (rest ? "initial_state is an equilibrium (the flow is zero there)"
                                      : "the flow at initial_state has no time scale (its Jacobian is zero or "
                                        "not finite)") +
                                ": no period to read; give frequencies: [{guess: value}]",
                            at);
  return 2 * M_PI / rate;
}

// The default guess of an autonomous model that gives no 'frequencies'
// (rmhb/METHOD.md s.20): 2 pi over the period of the trajectory from
// initial_state, the time between its last two returns to the section
// through initial_state normal to the flow (on a periodic orbit through it,
// the first return; approaching a limit cycle, the intervals converge to its
// period). The horizon starts at 20 time scales of the flow and grows 8-fold
// up to 10^5 of them while fewer than three returns are seen.
double FrequencyFromTrajectory(const model::ModelDefinition& definition, const Model& p, std::string* note) {
  const model::SourceLocation at = definition.initial_state.empty() ? model::SourceLocation{definition.source, 1, 1}
                                                                    : definition.initial_state[0].second.where;
  if (!p.original)
    throw model::ModelError("no 'frequencies' and the original equations cannot be integrated (" +
                                (p.original_error.empty() ? std::string("no ODE") : p.original_error) +
                                "): give frequencies: [{guess: value}]",
                            at);
  const integrators::OdeSystem ode = p.original(p.problem.frequencies);
  // A file without initial_state starts at its guess's state, at rest
  // without one, which a self-excited model has as its equilibrium: the
  // trajectory starts next to it, as every record of the model's own motion
  // does (RecordStart). A given initial_state at an equilibrium is refused
  // (FlowTimeScale): a conservative family has no orbit to prefer.
  double perturbation = 0;
  const Eigen::VectorXd y0 = definition.initial_state.empty() ? RecordStart(p, &perturbation) : p.initial_state;
  const double scale = FlowTimeScale(ode, y0, at);
  integrators::IntegratorOptions io;
  io.method = integrators::IntegratorOptions::Method::kBdf;  // stiff or not
  io.relative_tolerance = 1e-10;
  io.absolute_tolerance = 1e-12;
  std::vector<double> returns;
  double horizon = 20 * scale;
  for (; horizon <= 1e5 * scale; horizon *= 8) {
    returns = integrators::SectionReturns(ode, y0, horizon, io);
    if (returns.size() >= 3) break;
  }
  char text[192];
  if (returns.empty()) {
    std::snprintf(text, sizeof text, "%.3g", std::min(horizon, 1e5 * scale));
    throw model::ModelError(std::string("no 'frequencies', and the trajectory from initial_state does not come "
                                        "back to it (no return to its section in t <= ") +
                                text + "): give frequencies: [{guess: value}]",
                            at);
  }
  const std::size_t last = returns.size();
  const double period = last >= 2 ? returns[last - 1] - returns[last - 2] : returns[0];
  std::snprintf(text, sizeof text,
                "default guess w = %.9g: the trajectory from initial_state%s, period %.9g between its "
                "returns %zu and %zu to the section through its start",
                2 * M_PI / period, perturbation != 0 ? " + 0.1 (an equilibrium)" : "", period, last - 1, last);
  *note = text;
  return 2 * M_PI / period;
}

// The model from its parsed file: `reload` recasts the same definition with
// other values, never reading or parsing the file again.
Model ModelFromDefinition(const std::shared_ptr<const model::ModelDefinition>& parsed,
                          const std::map<std::string, double>& overrides, EquationsRoute route) {
  const model::ModelDefinition& definition = *parsed;
  auto recast = std::make_shared<model::RecastResult>(model::Recast(definition, overrides));
  Model p;
  p.name = recast->model_name;
  p.from_file = true;
  for (const auto& e : definition.equations) p.equation += (p.equation.empty() ? "" : "; ") + e.text;
  p.problem = recast->problem;
  p.default_order = p.problem.frequencies.size() == 1 ? 25 : 7;
  p.guess = [recast](int order) { return recast->InitialGuess(order); };
  if (recast->original && recast->original->is_dae()) {
    p.original_dae = [recast](const std::vector<double>& w) {
      model::OriginalSystem bound = *recast->original;
      bound.BindFrequencies(w);
      return integrators::DaeSystem{bound.dimension, bound.residual, bound.differential};
    };
    // For commands that only integrate ODEs (they test `original`).
    p.original_error = "the original equations are a DAE (a variable appears without derivatives); "
                       "only IDA integrates them";
  } else if (recast->original) {
    p.original = [recast](const std::vector<double>& w) {
      model::OriginalSystem bound = *recast->original;
      bound.BindFrequencies(w);
      return integrators::OdeSystem{bound.dimension, bound.rhs};
    };
    if (recast->original->num_switches > 0)
      p.original_switched = [recast](const std::vector<double>& w) {
        model::OriginalSystem bound = *recast->original;
        bound.BindFrequencies(w);
        return integrators::SwitchedOdeSystem{bound.dimension, bound.num_switches, bound.switched_rhs, bound.next_mode, nullptr};
      };
  }
  if (recast->original) {
    p.state = [recast](const HarmonicSolution& s, double t) {
      const std::vector<double> v = recast->original->StateFromSolution(s, t);
      return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<long>(v.size())).eval();
    };
    p.state_names = recast->original->state_names;
    // User variable v's derivative j: a state while j is below its order,
    // then the time derivative of its highest state.
    const std::vector<int> orders = recast->original->orders;
    for (size_t v = 0; v < orders.size(); ++v)
      p.state_derivatives = std::max(p.state_derivatives, recast->user_derivatives[v] - orders[v] + 1);
    p.variables = [recast, orders](const std::vector<double>& theta, const std::vector<Eigen::VectorXd>& y) {
      std::vector<double> user;
      int offset = 0;
      for (size_t v = 0; v < orders.size(); offset += orders[v], ++v)
        for (int j = 0; j <= recast->user_derivatives[v]; ++j)
          user.push_back(j < orders[v] ? y[0](offset + j) : y[j - orders[v] + 1](offset + orders[v] - 1));
      return recast->variables_from_user(theta, user);
    };
  } else {
    p.original_error = recast->original_error;
  }
  p.recast_report = recast->Report();
  if (recast->original) {
    p.state_sources = recast->original->sources;
    if (recast->initial_state)
      p.initial_state = Eigen::Map<const Eigen::VectorXd>(recast->initial_state->data(),
                                                          static_cast<long>(recast->initial_state->size()));
    else
      p.initial_state = p.state(p.guess(p.default_order), 0.0);
  }
  p.num_user_conditions = recast->num_user_conditions;
  p.definition = parsed;
  p.overrides = overrides;
  p.reload = [parsed, route](const model::ParameterValues& values) {
    return ModelFromDefinition(parsed, values, route);
  };
  if (route == EquationsRoute::kRecast)
    p.reload_problem = [parsed](const model::ParameterValues& values) {
      return model::Recast(*parsed, values, true).problem;
    };
  ChooseEquations(recast, route, &p);
  if (p.equations == "recast") p.frequency_parameters = recast->frequency_parameters;
  if (definition.frequency_from_trajectory) {
    std::string note;
    char guess[32];
    std::snprintf(guess, sizeof guess, "%.17g", FrequencyFromTrajectory(definition, p, &note));
    Model with = ModelFromDefinition(std::make_shared<const model::ModelDefinition>(model::ParseModel(
                                         definition.text, definition.source, {}, guess)),
                                     overrides, route);
    with.frequency_note = note;
    // Other parameters, another trajectory: the guess is read again.
    with.reload = p.reload;
    with.reload_problem = nullptr;
    return with;
  }
  if (NeedsDefaultConditions(definition, p)) {
    std::string note;
    const std::vector<std::string> conditions = DefaultConditions(definition, p, &note);
    Model with = ModelFromDefinition(std::make_shared<const model::ModelDefinition>(model::ParseModel(
                                         definition.text, definition.source, conditions,
                                         definition.frequency_guess)),
                                     overrides, route);
    with.conditions_note = note;
    return with;
  }
  // The recast's auxiliaries can fail where the equations as written do not
  // (a steep tanh(20 x') recast through its derivative): SolveModel's last resort.
  if (route == EquationsRoute::kRecast && recast->original_problem && HasAuxiliaries(recast->problem))
    p.original_equations = [parsed, overrides] {
      return ModelFromDefinition(parsed, overrides, EquationsRoute::kOriginal);
    };
  DetectInvariances(&p);
  return p;
}

}  // namespace

Model LoadModel(const std::string& path, const std::map<std::string, double>& overrides, EquationsRoute route) {
  return ModelFromDefinition(std::make_shared<const model::ModelDefinition>(model::LoadModelFile(path)), overrides,
                             route);
}

namespace {

model::ParameterValues AllOverrides(const Model& model, const model::ParameterValues& values) {
  if (!model.reload) throw std::invalid_argument("the model '" + model.name + "' cannot be rebuilt with other parameters");
  model::ParameterValues all = model.overrides;
  for (const auto& [name, value] : values) all[name] = value;
  return all;
}

// SetFrequencies on the problem alone.
void SetProblemFrequencies(const std::string& text, HarmonicBalanceProblem* problem) {
  const int bases = static_cast<int>(problem->frequencies.size());
  std::vector<std::string> items;
  std::string item;
  for (char c : text + ",") {
    if (c == ',') items.push_back(item), item.clear();
    else item += c;
  }
  if (static_cast<int>(items.size()) != bases)
    throw std::invalid_argument("--frequencies: the model has " + std::to_string(bases) +
                                " base frequencies, got " + std::to_string(items.size()));
  if (problem->unknown_frequency.empty()) problem->unknown_frequency.assign(bases, false);
  for (int b = 0; b < bases; ++b) {
    const bool unknown = !items[b].empty() && items[b][0] == '?';
    const double w = ParseNumberList(unknown ? items[b].substr(1) : items[b], "--frequencies")[0];
    if (!(w > 0)) throw std::invalid_argument("--frequencies: frequencies must be > 0");
    problem->frequencies[b] = w;
    if (unknown) problem->unknown_frequency[b] = true;
  }
}

}  // namespace

Model WithParameters(const Model& model, const model::ParameterValues& values) {
  Model out = model.reload(AllOverrides(model, values));
  if (!model.frequency_settings.empty()) SetFrequencies(model.frequency_settings, &out);
  return out;
}

HarmonicBalanceProblem ProblemWithParameters(const Model& model, const model::ParameterValues& values) {
  if (!model.reload_problem) return WithParameters(model, values).problem;
  HarmonicBalanceProblem problem = model.reload_problem(AllOverrides(model, values));
  if (!model.frequency_settings.empty()) SetProblemFrequencies(model.frequency_settings, &problem);
  return problem;
}

void SetFrequencies(const std::string& text, Model* model) {
  SetProblemFrequencies(text, &model->problem);
  model->frequency_settings = text;
}

namespace {
void RequireOriginal(const Model& source) {
  if (!source.original && !source.original_dae)
    throw std::invalid_argument("cannot integrate the model: " + source.original_error);
}
}  // namespace

HarmonicSolution GuessAtOrder(const Model& model, int order) {
  const HarmonicSolution guess = model.guess(order);
  std::vector<double> w = guess.frequencies();
  for (size_t b = 0; b < w.size(); ++b) w[b] = model.problem.frequencies[b];
  return guess.WithFrequencies(w);
}

void DetectInvariances(Model* model) {
  // Half-turns for one base only without a user's conditions (recast pins
  // are equivariant: HalfTurnsKeepConditions).
  const HarmonicBalanceProblem& p = model->problem;
  const size_t bases = p.frequencies.size();
  if (model->invariances.empty() && bases > 0 && HalfTurnsKeepConditions(p))
    model->invariances = DetectHalfTurnSymmetries(p.system, static_cast<int>(bases));
  // Time reversals keep t = 0 where it is: conditions there are equivariant.
  for (HalfTurnSymmetry& reversal : DetectTimeReversals(p.system, p.frequencies)) {
    bool listed = false;
    for (const HalfTurnSymmetry& s : model->invariances) listed = listed || s.Mask() == reversal.Mask();
    if (!listed) model->invariances.push_back(std::move(reversal));
  }
}

int ImposeGuessSymmetries(const HarmonicSolution& guess, Model* model) {
  // Not one whose subspace violates a condition (x(0) = 1 for an odd x).
  std::vector<HalfTurnSymmetry> candidates;
  for (const HalfTurnSymmetry& s : model->invariances)
    if (ViolatesNoCondition(s, model->problem.conditions)) candidates.push_back(s);
  const std::vector<HalfTurnSymmetry> held = SymmetriesOf(guess, candidates, model->problem.symmetries);
  model->problem.symmetries.insert(model->problem.symmetries.end(), held.begin(), held.end());
  return static_cast<int>(held.size());
}

const char* OriginalIntegrator(const Model& source, integrators::IntegratorOptions::Method method) {
  return source.original_dae ? "IDA BDF" : method == integrators::IntegratorOptions::Method::kBdf ? "CVODE BDF"
                                                                                               : "CVODE Adams";
}

const char* OriginalIntegrator(const Model& source) {
  return OriginalIntegrator(source, source.stiff ? integrators::IntegratorOptions::Method::kBdf
                                                 : integrators::IntegratorOptions::Method::kAdams);
}

Model OriginalEquationsOf(const Model& model) {
  if (!model.original_equations)
    throw std::invalid_argument("the model '" + model.name + "' has no original-equations twin");
  Model original = model.original_equations();
  if (!model.frequency_settings.empty()) SetFrequencies(model.frequency_settings, &original);
  if (original.conditions_note.empty()) original.conditions_note = model.conditions_note;
  if (original.frequency_note.empty()) original.frequency_note = model.frequency_note;
  original.equations_note = "original: the recast reached no physical solution";
  return original;
}

Eigen::VectorXd RecordStart(const Model& model, double* perturbation) {
  *perturbation = 0;
  Eigen::VectorXd y0 = model.initial_state;
  if (!model.original || y0.size() == 0) return y0;
  const integrators::OdeSystem ode = model.original(model.problem.frequencies);
  const double period =
      2 * M_PI / *std::min_element(model.problem.frequencies.begin(), model.problem.frequencies.end());
  const double scale = std::max(1.0, y0.cwiseAbs().maxCoeff());
  Eigen::VectorXd ydot(y0.size());
  // Irrational fractions of the period: no forcing term vanishes at all of them.
  // A model that cannot be evaluated there is left to the integration to report.
  try {
    for (double fraction : {0.0, 0.1234567, 0.3819660, 0.7071068}) {
      ode.rhs(fraction * period, y0.data(), ydot.data());
      if (!(ydot.cwiseAbs().maxCoeff() <= 1e-14 * scale)) return y0;
    }
  } catch (const std::exception&) {
    return y0;
  }
  *perturbation = kRestPerturbation;
  y0.array() += kRestPerturbation;
  return y0;
}

frequency_id::Signal RecordOriginal(const Model& source, const std::vector<double>& w,
                                    const Eigen::VectorXd& y0, const seeding::RecordOptions& record) {
  RequireOriginal(source);
  return source.original_dae ? seeding::RecordTrajectory(source.original_dae(w), y0, record, source.state_names)
                             : seeding::RecordTrajectory(source.original(w), y0, record, source.state_names);
}

namespace {

// Per thinning d (1, 2, 4, ... up to `oversampling`): the strongest line of
// the record's Hann^4 spectrum (channel means removed) at or above
// kTopBand of the thinned record's Nyquist frequency, over the strongest
// line overall. A smooth motion's harmonics decay: the band below Nyquist
// bounds what lies beyond it, and is wide enough to hold a harmonic at 12
// samples per period of an odd-harmonic motion.
constexpr double kTopBand = 0.75;
std::vector<double> TopBandLevels(const frequency_id::Signal& record, int oversampling) {
  const Eigen::MatrixXd centred = record.samples.rowwise() - record.samples.colwise().mean();
  frequency_id::SpectrumAnalyzer analyzer({record.t0, record.dt, record.num_samples()}, frequency_id::Window(4));
  const Eigen::VectorXd& a = analyzer.Compute(centred);
  const int bins = analyzer.num_bins();
  const double strongest = a.maxCoeff();
  std::vector<double> levels;
  for (int d = 1; d <= oversampling; d *= 2) {
    const int first = static_cast<int>(kTopBand * (bins - 1) / d);
    levels.push_back(strongest > 0 ? a.tail(bins - first).maxCoeff() / strongest : 0.0);
  }
  return levels;
}

}  // namespace

frequency_id::IdentificationOptions RecordIdentificationOptions() {
  frequency_id::IdentificationOptions id;
  id.relative_threshold = kRecordLineThreshold;
  id.bases.relative_tolerance_floor = 1e-10;
  return id;
}

bool RecordSampling::resolved() const { return top_band <= kRecordLineThreshold; }

frequency_id::Signal RecordUnaliased(const Model& model, const std::vector<double>& w, const Eigen::VectorXd& y0,
                                     seeding::RecordOptions record, RecordSampling* sampling) {
  frequency_id::Signal asked = RecordOriginal(model, w, y0, record);
  *sampling = {1, 1, TopBandLevels(asked, 1)[0]};
  if (sampling->resolved()) return asked;
  record.dt /= kRecordOversampling;
  frequency_id::Signal dense = RecordOriginal(model, w, y0, record);
  const std::vector<double> levels = TopBandLevels(dense, kRecordOversampling);
  *sampling = {kRecordOversampling, 1, levels[0]};
  for (size_t i = 1; i + 1 < levels.size() && levels[i] <= kRecordLineThreshold; ++i)
    *sampling = {kRecordOversampling, 1 << i, levels[i]};
  if (sampling->thinning == 1) return dense;
  frequency_id::Signal kept = std::move(dense);
  kept.samples = kept.samples(Eigen::seq(0, Eigen::last, sampling->thinning), Eigen::all).eval();
  kept.dt *= sampling->thinning;
  return kept;
}

integrators::IntegrationResult SimulateOriginal(const Model& model, const std::vector<double>& w,
                                                const Eigen::VectorXd& y0, const std::vector<double>& times,
                                                const integrators::IntegratorOptions& options) {
  RequireOriginal(model);
  return model.original_dae
             ? integrators::IntegrateDae(model.original_dae(w), y0, Eigen::VectorXd::Zero(y0.size()), 0.0, times, options)
             : integrators::IntegrateOde(model.original(w), y0, 0.0, times, options);
}

integrators::ValidationReport ValidateOriginal(const Model& source, const HarmonicSolution& solution, double t_end,
                                               int samples, const StateOfSolution& state) {
  RequireOriginal(source);
  const StateOfSolution& map = state ? state : source.state;
  auto claimed = [&](double t) { return map(solution, t); };
  const std::vector<double>& w = solution.frequencies();
  if (source.original_dae) return integrators::ValidateDaeTrajectory(source.original_dae(w), claimed, t_end, samples);
  if (source.original_switched)
    return integrators::ValidateSwitchedTrajectory(source.original_switched(w), claimed, t_end, samples);
  return integrators::ValidateTrajectory(source.original(w), claimed, t_end, source.stiff, samples);
}

ValidationVerdict JudgeValidation(const Model& model, const HarmonicSolution& solution,
                                  const integrators::ValidationReport& report, double t_end, double tolerance) {
  ValidationVerdict v;
  v.tolerance = tolerance;
  v.scale = std::numeric_limits<double>::min();
  for (int i = 0; i <= 256; ++i) v.scale = std::max(v.scale, model.state(solution, t_end * i / 256).lpNorm<Eigen::Infinity>());
  v.relative_error = report.ok ? report.max_error / v.scale : std::numeric_limits<double>::infinity();
  v.ok = report.ok && v.relative_error <= tolerance;
  return v;
}

std::string ValidationVerdict::Describe() const {
  char text[160];
  std::snprintf(text, sizeof text, "%s: relative error %.2e %s tolerance %.0e (max |state| %.3g)",
                ok ? "ok" : "EXCEEDS", relative_error, ok ? "<=" : ">", tolerance, scale);
  return text;
}

}  // namespace rmhb
