#ifndef RMHB_PIPELINE_MODEL_H_
#define RMHB_PIPELINE_MODEL_H_

// A model as every study sees it, whatever it came from: the harmonic
// balance problem (the recast, rmhb/model/recast.h), a starting guess at any
// order, the original equations with the integrator they need (CVODE for an
// ODE, IDA for a DAE) for validation and trajectories, and the map from a
// solution to the original state. LoadModel makes one from a model file
// (rmhb/model/FORMAT.md); a program can fill one by hand (the CLI's built-in
// examples do).

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "frequency_id/frequency_identification.h"
#include "frequency_id/signal.h"
#include "integrators/integration_result.h"
#include "integrators/integrator_options.h"
#include "integrators/ode_system.h"
#include "integrators/switched_integration.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_solution.h"
#include "rmhb/model/model_definition.h"
#include "rmhb/model/original_system.h"
#include "rmhb/pipeline/reference.h"
#include "rmhb/seeding/identified_guess.h"

namespace rmhb {

struct Model {
  std::string name;
  std::string equation;  // as the user wrote it
  bool from_file = false;
  HarmonicBalanceProblem problem;
  int default_order = 20;
  std::function<HarmonicSolution(int order)> guess;
  // The original equations with the base frequencies bound to `w` (forcing
  // terms need the solved values), and the state a solution predicts.
  std::function<integrators::OdeSystem(const std::vector<double>& w)> original;
  // Set instead of `original` for a model with algebraic equations: the DAE
  // F(t, y, y') = 0 for IDA.
  std::function<integrators::DaeSystem(const std::vector<double>& w)> original_dae;
  // Set besides `original` for piecewise-smooth equations (max, abs, ...):
  // the same ODE with its switches, for event-located integration
  // (ValidateOriginal uses it: the reference is not smeared across a kink).
  std::function<integrators::SwitchedOdeSystem(const std::vector<double>& w)> original_switched;
  std::function<Eigen::VectorXd(const HarmonicSolution&, double t)> state;
  std::vector<std::string> state_names;
  // Every variable from the state and its derivatives on a torus.
  seeding::StateToVariables variables;
  int state_derivatives = 0;
  bool stiff = false;
  std::string original_error;  // why there is no original system, if so
  std::string recast_report;   // the polynomial system, readable
  // Where the model starts (simulate, identify, analyze): its initial state,
  // or else the guess's state at t = 0. Empty only when there is no
  // original system.
  Eigen::VectorXd initial_state;
  // Where each original state lives among the recast variables, and how
  // many of the problem's conditions are the user's (the rest pin
  // auxiliaries, METHOD.md eq. 24).
  std::vector<model::StateSource> state_sources;
  int num_user_conditions = 0;
  // The parsed model (model files only): for symbolic variants such as the
  // Taylor-expanded system.
  std::shared_ptr<const model::ModelDefinition> definition;
  model::ParameterValues overrides;
  // Exact answers, when the model has them (the bundled examples).
  ExactReference reference;
  // The same model with other parameter overrides (all of them, not only
  // the changed ones): set by LoadModel and the built-in examples
  // (examples/example_model.h), empty for a hand-made model. Continuation
  // and sweeps rebuild the model through it (WithParameters).
  std::function<Model(const model::ParameterValues& overrides)> reload;
  // reload(overrides).problem (before frequency settings) without the rest
  // of the model, where that is cheaper: a model file on the recast route
  // recasts the problem alone (model::Recast's problem_only). Empty: use
  // reload. ProblemWithParameters uses it.
  std::function<HarmonicBalanceProblem(const model::ParameterValues& overrides)> reload_problem;
  // The base frequencies set by SetFrequencies, re-applied by WithParameters.
  std::string frequency_settings;
  // Parameter -> base index: the parameters that enter `problem` only as
  // problem.frequencies[base] (a forcing frequency), so that WithParameters
  // changing one of them changes nothing else in `problem`. A model file's
  // are proved on its recast (model::RecastResult::frequency_parameters; on
  // the recast route only), a built-in example's are declared with its
  // parameters (examples/example_system.h, checked by its test). A
  // continuation in one of them sets the frequency instead of rebuilding
  // the model at every value (ModelContinuationProblem, METHOD.md s.19).
  std::map<std::string, int> frequency_parameters;
  // The equations `problem` holds: "recast" or "original" (LoadModel's
  // route), and why kAuto chose them or kOriginal was not possible.
  std::string equations = "recast";
  std::string equations_note;
  // A model file on the recast whose recast needs auxiliaries: the same model
  // (parameters as loaded) on its original equations, for SolveModel to fall
  // back on when the recast reaches no physical solution. Empty otherwise.
  std::function<Model()> original_equations;
  // Set when the file gives no conditions and the model got default ones
  // (which, and why: ModelFromDefinition, rmhb/METHOD.md s.20).
  std::string conditions_note;
  // Set when an autonomous file gives no 'frequencies': the guess read off
  // the trajectory from initial_state, and how (rmhb/METHOD.md s.20).
  std::string frequency_note;
  // The conditions the model got by default (empty without a note), as
  // "x(0) = (1.2)", ...: what a report prints next to the note.
  std::vector<std::string> DefaultConditions() const {
    std::vector<std::string> out;
    if (!conditions_note.empty())
      for (int c = 0; c < num_user_conditions; ++c) out.push_back(problem.conditions[c].description);
    return out;
  }
  // Symmetries of the equations (not imposed on `problem`): the half-wave
  // map x -> -x, t -> t + T/2 of the original equations when they have it.
  std::vector<HalfTurnSymmetry> invariances;
};

// The model with `values` on top of its overrides (and its frequency
// settings kept). Throws std::invalid_argument for a model that cannot be
// rebuilt (no `reload`) or an unknown parameter, model::ModelError for a
// model file's errors.
Model WithParameters(const Model& model, const model::ParameterValues& values);
// WithParameters(model, values).problem, through Model::reload_problem when
// the model has one (continuation rebuilds the problem ~11 times per point
// and needs nothing else there). Throws as WithParameters.
HarmonicBalanceProblem ProblemWithParameters(const Model& model, const model::ParameterValues& values);

// "w1,?w2": the values of known base frequencies and the guesses of unknown
// ones ('?' makes a base unknown), one per base, each > 0. Throws
// std::invalid_argument naming the item (as --frequencies).
void SetFrequencies(const std::string& text, Model* model);

// Which equations harmonic balance solves for a model file (METHOD.md s.13):
//  - kRecast: the polynomial recast, RHB with the alias-free sample count
//    (Theorem 1: classical HB to round-off, no spurious solutions);
//  - kOriginal: the equations as written, evaluated pointwise (HB-AFT with
//    exact compiled partial derivatives): no auxiliaries, so a third to a
//    half of the recast's unknowns for sin, sqrt, 1/x terms, and no
//    truncation of the auxiliaries (the forced pendulum at N = 20: 4.2e-12
//    from the true orbit against the recast's 7.1e-10); aliasing is measured after each solve
//    on a grid twice as fine (HarmonicBalanceSummary::alias_residual);
//  - kAuto: the original equations when the recast needed auxiliaries and
//    the original route exists, else the recast (a polynomial model is its
//    own recast: RHB keeps its guarantee at the same cost).
enum class EquationsRoute { kRecast, kOriginal, kAuto };
const char* ToString(EquationsRoute route);  // "recast", "original", "auto"
// Throws std::invalid_argument for another name.
EquationsRoute ParseEquationsRoute(const std::string& name);

// A model file with parameter overrides. Throws model::ModelError
// (file:line:column) or std::invalid_argument (an unknown parameter, or
// kOriginal for a model whose equations cannot be solved as written: the
// message says why).
Model LoadModel(const std::string& path, const std::map<std::string, double>& overrides = {},
                EquationsRoute route = EquationsRoute::kRecast);

// The model's starting guess at `order`, with the problem's frequencies
// (which a caller may have changed since the model was loaded).
HarmonicSolution GuessAtOrder(const Model& model, int order);

// Sets model->invariances, when empty, to the half-turn symmetries of its
// equations (DetectHalfTurnSymmetries) for two or more bases, or for one
// base when the problem has no conditions (a forced system: conditions at
// t = 0 are not equivariant under t -> t + T/2): LoadModel and
// the built-in examples call it, so that a model file and an example with
// the same equations impose the same symmetries.
void DetectInvariances(Model* model);

// Imposes on model->problem each of model->invariances that `guess` has
// (its harmonics of the other parity at most 1e-14 of its largest
// coefficient; not a guess at rest) and is not a composition of those
// already imposed, and returns how many. Exact, not an approximation: the
// equations are equivariant, so Newton's iterates from a symmetric guess
// stay symmetric and the solve ends where the full solve would, with half
// the unknowns (an eighth of the factorisation) per symmetry.
int ImposeGuessSymmetries(const HarmonicSolution& guess, Model* model);

// The model's twin on its original equations (Model::original_equations)
// with what the caller set on top of loading (frequency settings) and the
// model's notes; throws std::invalid_argument when it has none.
Model OriginalEquationsOf(const Model& model);

// Where a record that looks for the model's own motion (identify, analyze)
// starts: its initial_state, left by kRestPerturbation in every state
// component when that is an equilibrium of the original equations (f(t, y0)
// = 0 at several times of the slowest period: a forced model's rest is not
// one), since the motion from an equilibrium never leaves it while a
// self-excited orbit is reached from next to it (a file with neither
// initial_state nor guess starts at rest). Sets *perturbation to what was
// added (0: none). Explicit ODEs only: a DAE's algebraic states must stay
// consistent, its start is taken as given.
constexpr double kRestPerturbation = 0.1;
Eigen::VectorXd RecordStart(const Model& model, double* perturbation);

// The model's original equations integrated by what they need: IDA for a
// DAE, else CVODE (BDF when the model is stiff). They throw
// std::invalid_argument with original_error when there are none.
const char* OriginalIntegrator(const Model& model);  // "IDA BDF", "CVODE BDF", "CVODE Adams"
// The same for an ODE model integrated by `method` instead of its own choice.
const char* OriginalIntegrator(const Model& model, integrators::IntegratorOptions::Method method);
frequency_id::Signal RecordOriginal(const Model& model, const std::vector<double>& w, const Eigen::VectorXd& y0,
                                    const seeding::RecordOptions& record);
// How RecordUnaliased sampled: the trajectory was integrated and sampled
// `oversampling` times as often as asked, then every `thinning`-th sample
// kept; `top_band` is the strongest line of the record's spectrum in the
// band below the kept rate's Nyquist frequency, over its strongest line.
struct RecordSampling {
  int oversampling = 1;
  int thinning = 1;
  double top_band = 0;
  bool resolved() const;  // top_band <= kRecordLineThreshold
};
// Lines weaker than this fraction of the strongest in a record of the model's
// integrated motion are not lines of the motion: CVODE's phase drift (~1e-11
// relative per period at rtol 1e-13) makes sidebands near 1e-9 of the
// strongest line over a long record (`rmhb identify pendulum` took them for
// lines of a second base, w2 = -1.7e-10), and a guess needs nothing that
// weak (Newton adds it).
constexpr double kRecordLineThreshold = 1e-8;
// Identification options for such a record: lines down to
// kRecordLineThreshold, and a line labelled when it is within 1e-10 of its
// lattice point relative (BaseSelectionOptions::relative_tolerance_floor):
// the drift also bends a harmonic's frequency off k w1 by more than its
// standard error claims (the Kepler orbit's second harmonic: 8.8e-12 off at
// an uncertainty of 5e-13, which made the harmonics a torus of two bases).
frequency_id::IdentificationOptions RecordIdentificationOptions();
// RecordOriginal at the asked rate; when the band below its Nyquist
// frequency holds a line above kRecordLineThreshold of the strongest, again
// at kRecordOversampling times that rate, thinned to every 2nd sample if its
// own band then is clean (never back to the asked rate). A line above
// Nyquist folds back to a frequency no base explains: Van der Pol at
// mu = 1.5 sampled 32 times per period had its harmonic 21 folded to 11.486,
// which identification took for a second base (rmhb/METHOD.md s.20).
constexpr int kRecordOversampling = 4;
frequency_id::Signal RecordUnaliased(const Model& model, const std::vector<double>& w, const Eigen::VectorXd& y0,
                                     seeding::RecordOptions record, RecordSampling* sampling);
// The original equations integrated from (0, y0) and sampled at `times`:
// IDA for a DAE (which makes y'(0) and the algebraic part of y0 consistent
// first), else CVODE with `options` (their method as given).
integrators::IntegrationResult SimulateOriginal(const Model& model, const std::vector<double>& w,
                                                const Eigen::VectorXd& y0, const std::vector<double>& times,
                                                const integrators::IntegratorOptions& options);

// The solution's state against a trajectory of the original equations from
// it at t = 0, over [0, t_end] at `samples` times (integrators/
// trajectory_validation.h). `state`: another map from a solution to the
// original state than the model's (a variant of its recast), if given.
using StateOfSolution = std::function<Eigen::VectorXd(const HarmonicSolution&, double t)>;
integrators::ValidationReport ValidateOriginal(const Model& model, const HarmonicSolution& solution, double t_end,
                                               int samples = 2001, const StateOfSolution& state = nullptr);

// The verdict on a validation: its max state error relative to the size of
// the state (max |y(t)| over the validated span) against a tolerance. "ok"
// only when the integration finished and the error is within it.
struct ValidationVerdict {
  bool ok = false;
  double relative_error = 0;  // max_error / scale
  double scale = 0;           // max |y(t)|, at least the smallest normal double
  double tolerance = 0;
  std::string Describe() const;  // "ok: relative error 3.2e-12 <= 1e-08" or "EXCEEDS: ..."
};
ValidationVerdict JudgeValidation(const Model& model, const HarmonicSolution& solution,
                                  const integrators::ValidationReport& report, double t_end, double tolerance);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_MODEL_H_
