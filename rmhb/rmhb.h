#ifndef RMHB_RMHB_H_
#define RMHB_RMHB_H_

// rmhb: periodic and quasi-periodic steady states by reconstruction harmonic
// balance. The one header a program needs (link rmhb::rmhb):
//   rmhb::Model model = rmhb::examples::LoadModelOrExample("oscillator.yaml", {{"mu", 0.5}});
//   rmhb::SolveSettings settings;  settings.order = 25;
//   rmhb::PreparedSolve p = rmhb::PrepareSolve(model, settings);
//   rmhb::SolveOptions solve;  solve.harmonic_balance = p.options;  solve.validate = true;
//   rmhb::SolveSummary s = rmhb::SolveModel(p.model, p.guess, solve);   // rmhb solve
//   auto analysis = rmhb::Analyze(model, {});   // integrate, identify, seed, solve, validate
// Every command of the rmhb tool is such a call (README, "The library"):
// SolveModel, ContinueModel, Analyze, Identify, Simulate, ConvergenceStudy,
// Census, Stability. The method: rmhb/METHOD.md. Every study takes Options
// with defaults and IsValid(), and returns a Summary with a status, a
// message, BriefReport(), FullReport() and ToJson(); misuse throws
// std::invalid_argument, non-convergence is a status.

#include "examples/example_model.h"
#include "integrators/floquet.h"
#include "integrators/lyapunov.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/continuation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"
#include "rmhb/model/model_error.h"
#include "rmhb/model/recast.h"
#include "rmhb/monte_carlo.h"
#include "rmhb/pipeline/analyze.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/census.h"
#include "rmhb/pipeline/convergence.h"
#include "rmhb/pipeline/identify.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/simulate.h"
#include "rmhb/pipeline/solve.h"
#include "rmhb/pipeline/stability.h"
#include "rmhb/pipeline/start.h"
#include "rmhb/pipeline/torus.h"
#include "rmhb/seeding/identified_guess.h"
#include "rmhb/version.h"

#endif  // RMHB_RMHB_H_
