// Settings shared by the CVODE (ODE) and IDA (DAE) front ends.

#ifndef RMHB_INTEGRATORS_INTEGRATOR_OPTIONS_H_
#define RMHB_INTEGRATORS_INTEGRATOR_OPTIONS_H_

namespace rmhb::integrators {

// The tightest relative tolerance worth asking for: below it round-off, not
// truncation, limits the accuracy, and a little lower (~2e-16) SUNDIALS
// refuses to step at all.
inline constexpr double kTightestRelativeTolerance = 1e-15;

struct IntegratorOptions {
  // Adams-Moulton (orders 1..12) is the accurate and cheap choice for
  // non-stiff problems such as the reference solutions harmonic balance is
  // validated against. BDF (orders 1..5) with a dense Newton solver is for
  // stiff problems, where Adams' step would be capped by stability rather
  // than accuracy. IDA is always BDF and ignores this field.
  enum class Method { kAdams, kBdf };
  Method method = Method::kAdams;

  // Defaults are tight because the integrators serve as references for
  // spectrally accurate harmonic-balance solutions. Both must be finite and
  // > 0. There is no hard floor in validation because SUNDIALS' own test is
  // state dependent: CVODE/IDA stop with status kFailure (CV_TOO_MUCH_ACC,
  // "too much accuracy requested") when u * ||y||_wrms > 1, u = 2.2e-16,
  // i.e. roughly when relative_tolerance < u. Measured on the pendulum over
  // 10 periods (Adams): 2.3e-16 still runs, 2e-16 fails. The error falls
  // steadily down to ~1e-15 (1.3e-10 at 1e-13, 1.5e-11 at 1e-14, 2.8e-12 at
  // 1e-15) and is erratic below (4.5e-13 at 5e-16, 1.6e-12 at 3e-16): round
  // off, not truncation, is then in charge. See kTightestRelativeTolerance.
  double relative_tolerance = 1e-12;
  double absolute_tolerance = 1e-14;

  // Budget of internal steps for the whole call, not per output interval
  // as in raw SUNDIALS: a long dense output grid must not multiply the
  // budget. Exceeding it is a kFailure, not an exception.
  long max_steps = 10'000'000;
  double max_step = 0.0;      // 0 = unlimited.
  double initial_step = 0.0;  // 0 = let SUNDIALS estimate it.
  int max_order = 0;          // 0 = method default (12 Adams, 5 BDF/IDA).

  // IDA only: run IDACalcIC (IDA_YA_YDP_INIT) to repair the algebraic
  // components of y0 and all of yp0 before integrating. Turn off only when
  // the caller guarantees consistency, e.g. when restarting from IDA output.
  bool compute_consistent_initial_condition = true;
};

}  // namespace rmhb::integrators

#endif  // RMHB_INTEGRATORS_INTEGRATOR_OPTIONS_H_
