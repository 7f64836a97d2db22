#ifndef RMHB_PIPELINE_SETTINGS_H_
#define RMHB_PIPELINE_SETTINGS_H_

// What every study that solves shares (solve, analyze, continuation,
// convergence, montecarlo, sweep): the order, the method, solver and
// sampling choices, the base frequencies; and the harmonic balance options
// and starting guess they make for a model. One place, so that order 25
// with HDHB means the same to every study, and the CLI's options and
// Python's keyword arguments, which fill these settings, mean the same too.
//   Model model = examples::LoadModelOrExample("duffing.yaml", {{"F", 0.5}});
//   SolveSettings settings;  settings.order = 30;
//   PreparedSolve p = PrepareSolve(std::move(model), settings);
//   // p.options and p.guess go to SolveModel, ContinueModel, Analyze, ...
// The sampling rule, solver, scaling and shapes are named as the core parses
// them (ParseSamplingRule, ParseSolverMethod, ParseScaling); error messages
// name each setting as the CLI's option that fills it (--order, ...).

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rmhb/harmonic_balance.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

struct SolveSettings {
  int order = -1;                // -1: the model's default
  int samples = -1;              // -1: by the method's rule
  // Set when a user gave the value, so that an explicit -1 is refused.
  bool order_given = false, samples_given = false;
  double residual_tol = 1e-15;   // max|F| at convergence
  std::string method = "rhb";    // rhb, hdhb, aft (SamplingRule)
  std::string solver = "auto";   // auto, newton, lm, tikhonov (SolverMethod)
  std::string scaling = "equilibrate";  // equilibrate, none (SolverOptions::scaling)
  std::string linear_solver = "auto";   // auto, dense, sparse, krylov (SolverOptions::linear_solver)
  int max_iterations = 100;
  bool allow_aliasing = false;
  std::string frequencies;  // "w1,w2"; "?w" marks an unknown with guess w (SetFrequencies)
  std::string sampling = "torus";  // torus, gcd (QuasiPeriodicSampling)
  std::string shape = "diamond";   // diamond, box (BasisShape)
  bool shape_given = false;        // an explicit shape overrides the model's own index set
  double tol = 0;  // > 0: choose the order automatically (HarmonicBalanceOptions::tolerance)
  // The accuracy target applied when neither --tol nor --order (nor
  // --samples) is given and the method is rhb: solve and analyze set it
  // (kDefaultTolerance); the studies that sweep many solves at one order
  // (continuation, sweep, montecarlo, convergence) leave it 0.
  double default_tol = 0;
  // The same for quasi-periodic models only (when default_tol is 0):
  // continuation sets it, so that a torus branch starts on the adaptive
  // index set of its first point (kept along the branch) rather than on the
  // default diamond, which misses a slow beat's band.
  double default_torus_tol = 0;
  static constexpr double kDefaultTolerance = 1e-10;
  std::string tol_quantity = "state";  // state, frequency (TargetQuantity)
  int max_order = 5000;  // the order selection's limit
  double max_jacobian_gib = 4;  // HarmonicBalanceOptions::max_jacobian_bytes in GiB
  // recast, original, auto (EquationsRoute, rmhb/pipeline/model.h): applied
  // when the model file is loaded (examples::LoadModelOrExample).
  std::string equations = "recast";
  // Empty when valid, else what is wrong (naming the CLI's option).
  std::string IsValid() const;
};

struct PreparedSolve {
  Model model;             // with the settings' frequencies
  HarmonicBalanceOptions options;
  HarmonicSolution guess;  // at options.order, with the problem's frequencies
};

// The settings checked (std::invalid_argument with IsValid's message), the
// frequencies applied to the model (SetFrequencies), the options built and
// the Jacobian's size checked (before a guess at that order is built), and
// the model's guess at that order.
PreparedSolve PrepareSolve(Model model, const SolveSettings& settings);

// "a,b,c" or "a:b:c" -> numbers; throws std::invalid_argument naming `what`
// and the item that is not a finite number.
std::vector<double> ParseNumberList(const std::string& text, const char* what);

// "name=value" -> (name, value), a parameter override as a user writes it;
// throws std::invalid_argument saying which is malformed or not a finite
// number.
std::pair<std::string, double> ParseAssignment(const std::string& text);
// Every "name=value", as parameter overrides (a later one wins).
std::map<std::string, double> ParseOverrides(const std::vector<std::string>& assignments);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_SETTINGS_H_
