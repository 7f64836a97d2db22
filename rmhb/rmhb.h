#ifndef RMHB_RMHB_H_
#define RMHB_RMHB_H_

// rmhb: periodic and quasi-periodic steady states by reconstruction harmonic
// balance. The one header a program needs (link rmhb::rmhb):
//   rmhb::Model model = rmhb::LoadModel("oscillator.yaml", {{"mu", 0.5}});
//   rmhb::HarmonicBalanceOptions options;  options.order = 25;
//   auto solved = rmhb::SolveHarmonicBalance(model.problem, rmhb::GuessAtOrder(model, 25), options);
//   auto check = rmhb::ValidateOriginal(model, *solved.solution, 100.0);
//   auto analysis = rmhb::Analyze(model, {});   // integrate, identify, seed, solve, validate
// The method: rmhb/METHOD.md. Every study takes Options with defaults and
// IsValid(), and returns a Summary with a status, a message and reports;
// misuse throws std::invalid_argument, non-convergence is a status.

#include "integrators/floquet.h"
#include "integrators/trajectory_validation.h"
#include "rmhb/continuation.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"
#include "rmhb/model/model_error.h"
#include "rmhb/model/recast.h"
#include "rmhb/monte_carlo.h"
#include "rmhb/pipeline/analyze.h"
#include "rmhb/pipeline/convergence.h"
#include "rmhb/pipeline/model.h"
#include "rmhb/pipeline/stability.h"
#include "rmhb/seeding/identified_guess.h"
#include "rmhb/version.h"

#endif  // RMHB_RMHB_H_
