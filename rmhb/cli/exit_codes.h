#ifndef RMHB_CLI_EXIT_CODES_H_
#define RMHB_CLI_EXIT_CODES_H_

// Documented in `rmhb --help` and the README; scripts rely on them.
namespace rmhb::cli {
constexpr int kExitOk = 0;
constexpr int kExitUsage = 1;         // unknown option, malformed argument
constexpr int kExitBadInput = 2;      // unknown model/parameter, invalid value, bad file
constexpr int kExitNotConverged = 3;  // the solver did not converge (residual reported)
constexpr int kExitInternal = 4;      // unexpected failure (a bug: please report)
constexpr int kExitNonPhysical = 5;   // converged, but not a solution of the model (which check says)
constexpr int kExitValidationExceeded = 6;  // validated against the original equations: error above --validate-tol
}  // namespace rmhb::cli

#endif  // RMHB_CLI_EXIT_CODES_H_
