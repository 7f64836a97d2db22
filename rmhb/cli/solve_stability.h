#ifndef RMHB_CLI_SOLVE_STABILITY_H_
#define RMHB_CLI_SOLVE_STABILITY_H_

// `solve --stability`: the Floquet multipliers of a converged periodic
// solution two independent ways, Hill's method on the harmonic balance
// linearisation (rmhb/hill_stability.h) and the CVODE monodromy matrix of
// the original equations (integrators/floquet.h), matched pairwise; the
// verdict is the monodromy's when it ran (it does not depend on the
// truncation), else Hill's. Where one of them does not apply (Hill: pinned
// auxiliaries or several base frequencies; monodromy: no original ODE) the
// object says why in its `note`.

#include <nlohmann/json.hpp>

#include "rmhb/cli/problem_source.h"
#include "rmhb/harmonic_solution.h"

namespace rmhb::cli {

// {"hill": {...} | {"note"}, "floquet": {...} | {"note"},
//  "max_multiplier_difference", "agree", "verdict"}; a verdict is stable,
// unstable, neutral (the largest non-trivial |mu| within 1e-6 of 1: a
// conservative orbit, or undecidable at this accuracy) or unknown.
nlohmann::json StabilityJson(const ProblemSource& source, const HarmonicSolution& solution);

// The same as readable lines, each starting with "stability".
void PrintStability(const nlohmann::json& stability);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_SOLVE_STABILITY_H_
