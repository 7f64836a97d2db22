#ifndef RMHB_PIPELINE_MONODROMY_H_
#define RMHB_PIPELINE_MONODROMY_H_

// The original equations' side of continuation on a model
// (rmhb/pipeline/model.h; ContinueModel in rmhb/pipeline/branch.h uses it),
// which gives stability at every point whatever the size:
//   ContinuationProblem p = ModelContinuationProblem(model_at, "w", 0.5, 3);
//   ContinuationSummary s = TraceBranch(p, guess, options);
// build() takes the model's harmonic balance problem at each value, and
// monodromy() the Floquet multipliers of its ORIGINAL equations along a
// point's solution (CVODE with the variational equations for an ODE,
// integrators/floquet.h; IDA for a DAE, integrators/dae_floquet.h). The
// monodromy's cost depends on the number of states, not on the harmonic
// order, which is why continuation takes it where Hill's eigenproblem would
// be large or does not apply (rmhb/continuation.h).

#include <functional>
#include <string>

#include "rmhb/continuation.h"
#include "rmhb/pipeline/model.h"

namespace rmhb {

struct ModelMonodromyOptions {
  // Integration tolerances of the variational equations. Continuation needs
  // the multipliers to decide stability and to locate a crossing of the
  // unit circle, not to 1e-12: at rtol 1e-10 they agree with Hill's method
  // to ~1e-9 on the test models (tests/pipeline/branch_test.cc).
  double relative_tolerance = 1e-10;
  double absolute_tolerance = 1e-12;
  std::string IsValid() const;
};

// The Floquet multipliers of the model's original equations along a
// periodic solution, integrated over its period 2 pi / w (w its base
// frequency) with the model's bases bound to period_multiple * w.
// ok = false (with the reason) when the model has no original equations or
// the integration fails; throws std::invalid_argument for a quasi-periodic
// solution or invalid options.
MonodromyResult ModelMonodromy(const Model& model, const HarmonicSolution& solution, int period_multiple = 1,
                               const ModelMonodromyOptions& options = {});

// A continuation problem on model_at(value): its harmonic balance problem
// and the monodromy of its original equations. The last few models are
// kept by value, so that the monodromy at a point reuses the build the
// corrector made there (a model file's recast is the expensive part).
ContinuationProblem ModelContinuationProblem(std::function<Model(double value)> model_at, std::string parameter,
                                             double start, double end, const ModelMonodromyOptions& options = {});
// The same on WithParameters(model, {{parameter, value}}) (the model is
// copied); build() takes ProblemWithParameters (a model file's problem
// alone, without its original equations' tapes). When the model has proved that `parameter` enters its problem
// only as a base frequency (Model::frequency_parameters; no --frequencies
// setting), build(value) is the problem at `start` with that frequency set
// to the value, without rebuilding the model, and only_frequencies_change is
// set (METHOD.md s.19); a value <= 0 is still the model's to refuse.
ContinuationProblem ModelContinuationProblem(const Model& model, const std::string& parameter, double start,
                                             double end, const ModelMonodromyOptions& options = {});

// A torus of a one-base model (rmhb/branch_switching.h: bases {w, w2}, the
// forcing on w) against a trajectory of the original equations from its
// state at t = 0 over [0, t_end] (the model's bases bound to w alone).
// ValidateOriginal binds every base of the solution, which a one-base
// model's equations refuse.
integrators::ValidationReport ValidateTorus(const Model& model, const HarmonicSolution& torus, double t_end,
                                            int samples = 2001);

}  // namespace rmhb

#endif  // RMHB_PIPELINE_MONODROMY_H_
