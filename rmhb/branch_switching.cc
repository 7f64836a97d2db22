#include "rmhb/branch_switching.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <Eigen/LU>

#include "rmhb/parameterized_residual.h"

namespace rmhb {
namespace {

using Clock = std::chrono::steady_clock;

// p with every time function's harmonic vector h replaced by map(h). A
// mapped harmonic that is negative or zero in its first non-zero entry is
// turned back (cos(-x) = cos x, sin(-x) = -sin x; cos 0 = 1, sin 0 = 0).
template <typename Map>
Polynomial MappedForcing(const Polynomial& p, Map map) {
  Polynomial out;
  for (const auto& [monomial, c] : p.terms()) {
    Polynomial term(c);
    if (monomial.time.kind != TimeFunction::Kind::kOne) {
      std::vector<int> h = map(monomial.time.harmonic);
      const auto first = std::find_if(h.begin(), h.end(), [](int k) { return k != 0; });
      const bool cosine = monomial.time.kind == TimeFunction::Kind::kCos;
      if (first == h.end()) {
        term = cosine ? term : Polynomial();
      } else {
        const double sign = *first < 0 && !cosine ? -1 : 1;
        if (*first < 0)
          for (int& k : h) k = -k;
        term = term * (cosine ? Polynomial::Cos(h) : Polynomial::Sin(h, sign));
      }
    }
    for (const auto& [slot, power] : monomial.factors)
      term = term * Pow(slot.derivative ? Polynomial::Derivative(slot.variable) : Polynomial::Variable(slot.variable),
                        power);
    out += term;
  }
  return out;
}

// p with every time function's harmonic multiplied by `factor`.
Polynomial ScaledForcing(const Polynomial& p, int factor) {
  return MappedForcing(p, [factor](std::vector<int> h) {
    for (int& k : h) k *= factor;
    return h;
  });
}

// Coefficient column of harmonic index i (>= 1): cos at 2i - 1, sin at 2i.
int CosColumn(int i) { return 2 * i - 1; }

// Inverse iteration for the near-null vector of J at a located bifurcation,
// restricted to `mask` (the new harmonics): J is block-diagonal between
// them and the old ones, and only the new block is singular there.
Eigen::VectorXd CriticalMode(const Eigen::MatrixXd& J, const Eigen::VectorXd& mask, double* residual) {
  const Eigen::MatrixXd A = J.rows() == J.cols() ? J : Eigen::MatrixXd(J.transpose() * J);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(A);
  Eigen::VectorXd v = mask.normalized();
  for (int it = 0; it < 6; ++it) {
    v = lu.solve(v).cwiseProduct(mask);
    const double norm = v.norm();
    if (!(norm > 0) || !std::isfinite(norm)) break;
    v /= norm;
  }
  const double scale = J.cwiseAbs().rowwise().sum().maxCoeff();
  *residual = scale > 0 && v.allFinite() ? (J * v).cwiseAbs().maxCoeff() / scale : HUGE_VAL;
  return v;
}

// The packed mask of the coefficients whose harmonic satisfies `selected`.
template <typename Selected>
Eigen::VectorXd HarmonicMask(const CollocationResidual& r, const HarmonicBasis& basis, int variables,
                             const std::vector<double>& frequencies, Selected selected) {
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(variables, basis.num_coefficients());
  for (int i = 1; i < basis.size(); ++i)
    if (selected(basis.harmonic(i))) m.middleCols(CosColumn(i), 2).setOnes();
  Eigen::VectorXd mask = r.Pack(m, std::vector<double>(frequencies.size(), 0.0));
  return mask;
}

HarmonicSolution Unpacked(const CollocationResidual& r, const HarmonicBasis& basis, const Eigen::VectorXd& x,
                          const std::vector<Variable>& variables) {
  Eigen::MatrixXd c;
  std::vector<double> w;
  r.Unpack(x, &c, &w);
  return HarmonicSolution(basis, w, c, variables);
}

// The stop rule of a doubled branch: its odd harmonics (the part the
// period-T branch does not have) pass through zero -- it merged back.
class MergeWatch {
 public:
  MergeWatch(HarmonicBasis basis) : basis_(std::move(basis)) {}
  std::string operator()(const ContinuationPoint& p) {
    const Eigen::MatrixXd& c = p.solution.coefficients();
    Eigen::MatrixXd odd = Eigen::MatrixXd::Zero(c.rows(), c.cols());
    for (int i = 1; i < basis_.size(); ++i)
      if (basis_.harmonic(i)[0] % 2) odd.middleCols(CosColumn(i), 2) = c.middleCols(CosColumn(i), 2);
    const double size = odd.norm(), total = c.norm();
    std::string why;
    if (++points_ > 2 && (size <= 1e-7 * total || (previous_.size() && (odd.array() * previous_.array()).sum() < 0))) {
      std::ostringstream out;
      out << "the period-2T branch merged back into the period-T branch near this point (its odd harmonics "
          << (size <= 1e-7 * total ? "vanished" : "changed sign") << ")";
      why = out.str();
    }
    if (size > 0) previous_ = odd;
    return why;
  }

 private:
  HarmonicBasis basis_;
  Eigen::MatrixXd previous_;
  int points_ = 0;
};

const ContinuationPoint& BifurcationAt(const ContinuationSummary& branch, const BifurcationPoint& b,
                                       BifurcationType type) {
  if (b.type != type) throw std::invalid_argument(std::string("branch switching: not a ") + ToString(type) + " point");
  if (b.point < 0 || b.point >= static_cast<int>(branch.points.size()))
    throw std::invalid_argument("branch switching: the bifurcation's point is not on the branch");
  return branch.points[b.point];
}

}  // namespace

HarmonicBalanceProblem PeriodMultiplied(const HarmonicBalanceProblem& problem, int factor) {
  if (factor < 1) throw std::invalid_argument("PeriodMultiplied: factor must be >= 1");
  HarmonicBalanceProblem out = problem;
  PolynomialSystem system;
  for (const Variable& v : problem.system.variables()) system.AddVariable(v.name, v.role, v.definition);
  for (const Equation& e : problem.system.equations())
    system.AddEquation(ScaledForcing(e.lhs, factor), e.balance_constant);
  out.system = std::move(system);
  for (double& w : out.frequencies) w /= factor;
  out.symmetries.clear();
  if (problem.definitions) {
    const VariableDefinitions old = problem.definitions;
    out.definitions.evaluate = [old, factor](const std::vector<double>& theta, const std::vector<Eigen::VectorXd>& z) {
      std::vector<double> angle = theta;
      for (double& a : angle) a *= factor;
      return old.evaluate(angle, z);
    };
  }
  return out;
}

HarmonicSolution PeriodMultipliedSolution(const HarmonicSolution& s, int factor) {
  if (s.basis().num_bases() != 1) throw std::invalid_argument("PeriodMultipliedSolution: periodic solutions only");
  const HarmonicBasis basis = HarmonicBasis::Periodic(factor * s.basis().order());
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(s.num_variables(), basis.num_coefficients());
  c.col(0) = s.coefficients().col(0);
  for (int i = 1; i < s.basis().size(); ++i) {
    const int j = basis.Find({factor * s.basis().harmonic(i)[0]});
    c.middleCols(CosColumn(j), 2) = s.coefficients().middleCols(CosColumn(i), 2);
  }
  std::vector<double> w = s.frequencies();
  for (double& v : w) v /= factor;
  return HarmonicSolution(basis, w, c, s.variables());
}

HarmonicBalanceProblem OnResonantBase(const HarmonicBalanceProblem& problem, const std::vector<int>& multiples) {
  const size_t bases = problem.frequencies.size();
  if (multiples.size() != bases || bases < 1)
    throw std::invalid_argument("OnResonantBase: one multiple per base frequency");
  for (int a : multiples)
    if (a < 0) throw std::invalid_argument("OnResonantBase: multiples must be >= 0");
  if (multiples[0] < 1) throw std::invalid_argument("OnResonantBase: the first multiple must be >= 1");
  HarmonicBalanceProblem out = problem;
  PolynomialSystem system;
  for (const Variable& v : problem.system.variables()) system.AddVariable(v.name, v.role, v.definition);
  auto map = [&multiples](const std::vector<int>& h) {
    int k = 0;
    for (size_t b = 0; b < h.size(); ++b) k += multiples[b] * h[b];
    return std::vector<int>{k};
  };
  for (const Equation& e : problem.system.equations()) system.AddEquation(MappedForcing(e.lhs, map), e.balance_constant);
  out.system = std::move(system);
  out.frequencies = {problem.frequencies[0] / multiples[0]};
  const bool unknown = !problem.unknown_frequency.empty() && problem.unknown_frequency[0];
  out.unknown_frequency = {unknown};
  out.symmetries.clear();
  if (problem.definitions) {
    const VariableDefinitions old = problem.definitions;
    out.definitions.evaluate = [old, multiples](const std::vector<double>& theta, const std::vector<Eigen::VectorXd>& z) {
      std::vector<double> angle(multiples.size());
      for (size_t b = 0; b < angle.size(); ++b) angle[b] = multiples[b] * theta[0];
      return old.evaluate(angle, z);
    };
  }
  return out;
}

DoubledBranch TraceDoubledBranch(const ContinuationProblem& problem, const ContinuationSummary& branch,
                                 const BifurcationPoint& pd, const ContinuationOptions& options) {
  const ContinuationPoint& at = BifurcationAt(branch, pd, BifurcationType::kPeriodDoubling);
  DoubledBranch out;
  const HarmonicSolution start = PeriodMultipliedSolution(at.solution, 2);
  const HarmonicBasis& basis = start.basis();
  const HarmonicBalanceProblem doubled = PeriodMultiplied(problem.build(pd.parameter), 2);
  std::vector<int> samples = SamplesForRule(doubled.system, basis, options.harmonic_balance.rule);
  CollocationResidual residual(doubled, basis, Sampling::Uniform(samples[0]));
  const Eigen::VectorXd x = residual.Pack(start.coefficients(), start.frequencies());
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  if (!residual.Evaluate(x, &F, &J)) {
    out.message = "the doubled problem cannot be evaluated at the period-doubling point";
    return out;
  }
  const Eigen::VectorXd mask = HarmonicMask(residual, basis, start.num_variables(), start.frequencies(),
                                            [](const std::vector<int>& k) { return k[0] % 2 != 0; });
  const Eigen::VectorXd v = CriticalMode(J, mask, &out.critical_mode_residual);
  if (!v.allFinite()) {
    out.message = "no critical mode on the odd harmonics (the doubled Jacobian's inverse iteration failed)";
    return out;
  }
  const HarmonicSolution direction = Unpacked(residual, basis, v, start.variables());

  ContinuationProblem twice = problem;
  twice.build = [build = problem.build](double value) { return PeriodMultiplied(build(value), 2); };
  twice.period_multiple = 2 * problem.period_multiple;
  twice.stop_when = MergeWatch(basis);
  ContinuationOptions o = options;
  o.harmonic_balance.samples.clear();
  out.branch = TraceBranchFrom(twice, pd.parameter, start, HarmonicSolution(basis, std::vector<double>(
                                                                                      start.frequencies().size(), 0.0),
                                                                            direction.coefficients(), start.variables()),
                               o);
  out.started = out.branch->points.size() > 1;
  out.message = out.started ? out.branch->BriefReport() : "the corrector failed on the first step: " + out.branch->message;
  return out;
}

HarmonicBalanceProblem WithSecondBase(const HarmonicBalanceProblem& problem, double w2) {
  if (problem.frequencies.size() != 1) throw std::invalid_argument("WithSecondBase: the problem must have one base");
  if (!(w2 > 0) || !std::isfinite(w2)) throw std::invalid_argument("WithSecondBase: w2 must be finite and > 0");
  HarmonicBalanceProblem out = problem;
  out.frequencies.push_back(w2);
  const bool first_unknown = !problem.unknown_frequency.empty() && problem.unknown_frequency[0];
  out.unknown_frequency = {first_unknown, true};
  out.symmetries.clear();
  if (problem.definitions) {
    const VariableDefinitions old = problem.definitions;
    out.definitions.evaluate = [old](const std::vector<double>& theta, const std::vector<Eigen::VectorXd>& z) {
      return old.evaluate({theta[0]}, z);
    };
  }
  return out;
}

std::string TorusOptions::IsValid() const {
  if (order < 0) return "order must be >= 0 (0: the branch's)";
  if (order_new < 1) return "order_new must be >= 1";
  if (!(amplitude > 0) || !std::isfinite(amplitude)) return "amplitude must be finite and > 0";
  if (max_iterations < 1) return "max_iterations must be >= 1";
  return "";
}

Eigen::RowVectorXd PhaseConditionRow(const CollocationResidual& residual, const HarmonicSolution& reference,
                                     int base) {
  const HarmonicBasis& basis = reference.basis();
  Eigen::MatrixXd d = Eigen::MatrixXd::Zero(reference.num_variables(), basis.num_coefficients());
  const Eigen::MatrixXd& c = reference.coefficients();
  // d/d theta_b of a cos(k.theta) + b sin(k.theta): (k_b b) cos - (k_b a) sin.
  for (int i = 1; i < basis.size(); ++i) {
    const int l = basis.harmonic(i)[base];
    d.col(CosColumn(i)) = l * c.col(CosColumn(i) + 1);
    d.col(CosColumn(i) + 1) = -l * c.col(CosColumn(i));
  }
  return residual.Pack(d, std::vector<double>(reference.frequencies().size(), 0.0)).transpose();
}

namespace {

// F(x, lambda) = 0 of the two-base problem, the phase condition
// p . x = 0 and the amplitude condition v . (x - x_ns) = epsilon, in
// y = (x, lambda) with x holding the unknown w2.
class TorusCorrector : public NonlinearProblem {
 public:
  TorusCorrector(ParameterizedResidual* f, Eigen::RowVectorXd phase, Eigen::VectorXd mode, Eigen::VectorXd x_ns,
                 double epsilon)
      : f_(f), phase_(std::move(phase)), mode_(std::move(mode)), x_ns_(std::move(x_ns)), epsilon_(epsilon) {}
  int num_unknowns() const override { return f_->n() + 1; }
  int num_residuals() const override { return f_->m() + 2; }
  bool Evaluate(const Eigen::VectorXd& y, Eigen::VectorXd* residual, Eigen::MatrixXd* jacobian) override {
    const int n = f_->n(), m = f_->m();
    if (!f_->Evaluate(y.head(n), y(n), &f_value_, jacobian ? &f_jacobian_ : nullptr)) return false;
    residual->resize(m + 2);
    residual->head(m) = f_value_;
    (*residual)(m) = phase_.dot(y.head(n));
    (*residual)(m + 1) = mode_.dot(y.head(n) - x_ns_) - epsilon_;
    if (jacobian) {
      jacobian->setZero(m + 2, n + 1);
      jacobian->topRows(m) = f_jacobian_;
      jacobian->row(m).head(n) = phase_;
      jacobian->row(m + 1).head(n) = mode_.transpose();
    }
    return true;
  }

 private:
  ParameterizedResidual* f_;
  Eigen::RowVectorXd phase_;
  Eigen::VectorXd mode_, x_ns_, f_value_;
  Eigen::MatrixXd f_jacobian_;
  double epsilon_;
};

// The periodic solution on the torus basis: harmonic k -> (k, 0).
HarmonicSolution EmbedOnTorus(const HarmonicSolution& s, const HarmonicBasis& basis, double w2) {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(s.num_variables(), basis.num_coefficients());
  c.col(0) = s.coefficients().col(0);
  for (int i = 1; i < s.basis().size(); ++i) {
    const int j = basis.Find({s.basis().harmonic(i)[0], 0});
    if (j > 0) c.middleCols(CosColumn(j), 2) = s.coefficients().middleCols(CosColumn(i), 2);
  }
  return HarmonicSolution(basis, {s.frequencies()[0], w2}, c, s.variables());
}

HarmonicBasis TorusBasis(int order, int order_new) {
  std::vector<std::vector<int>> harmonics;
  for (int l = 0; l <= order_new; ++l)
    for (int k = -order; k <= order; ++k)
      if (l > 0 || k > 0) harmonics.push_back({k, l});
  return HarmonicBasis::FromHarmonics(2, harmonics, order, "rectangle");
}

}  // namespace

std::string TorusStart::BriefReport() const {
  std::ostringstream out;
  out.precision(10);
  if (!solved) return "torus from the Neimark-Sacker point at " + parameter_name + " = " +
                      std::to_string(bifurcation_parameter) + ": not solved: " + message;
  out << "torus at " << parameter_name << " = " << parameter << " (Neimark-Sacker at " << bifurcation_parameter
      << "): bases " << torus->frequencies()[0] << ", " << torus->frequencies()[1] << " (w2 at the bifurcation "
      << w2_at_bifurcation << "), theta2 amplitude " << theta2_amplitude;
  out.precision(2);
  out << " (outermost harmonics " << theta2_tail << " of it)";
  out.precision(2);
  out << ", max|F| " << residual << ", " << iterations << " iterations, periodic orbit " << periodic_side
      << " on this side (" << (periodic_side == "unstable" ? "supercritical" : "subcritical") << ")";
  return out.str();
}

TorusStart TorusFromNeimarkSacker(const ContinuationProblem& problem, const ContinuationSummary& branch,
                                  const BifurcationPoint& ns, const ContinuationOptions& options,
                                  const TorusOptions& torus_options) {
  const auto clock = Clock::now();
  if (const std::string why = torus_options.IsValid(); !why.empty())
    throw std::invalid_argument("TorusFromNeimarkSacker: " + why);
  const ContinuationPoint& at = BifurcationAt(branch, ns, BifurcationType::kNeimarkSacker);
  TorusStart out;
  out.parameter_name = problem.parameter;
  out.bifurcation_parameter = ns.parameter;
  out.w2_at_bifurcation = ns.torus_frequency;
  const double w2 = ns.torus_frequency;
  const HarmonicBasis basis =
      TorusBasis(torus_options.order > 0 ? torus_options.order : at.solution.basis().order(), torus_options.order_new);
  auto build = [build = problem.build, w2](double value) { return WithSecondBase(build(value), w2); };
  const HarmonicBalanceProblem here = build(ns.parameter);
  const Sampling sampling = Sampling::Torus(SamplesForRule(here.system, basis, options.harmonic_balance.rule));
  const HarmonicSolution embedded = EmbedOnTorus(at.solution, basis, w2);

  // The critical mode with w2 fixed: the (k, +-1) block of the Jacobian.
  HarmonicBalanceProblem fixed = here;
  fixed.unknown_frequency[1] = false;
  CollocationResidual probe(fixed, basis, sampling);
  Eigen::VectorXd F;
  Eigen::MatrixXd J;
  if (!probe.Evaluate(probe.Pack(embedded.coefficients(), embedded.frequencies()), &F, &J)) {
    out.message = "the two-base problem cannot be evaluated at the Neimark-Sacker point";
    return out;
  }
  const Eigen::VectorXd mask = HarmonicMask(probe, basis, embedded.num_variables(), embedded.frequencies(),
                                            [](const std::vector<int>& k) { return std::abs(k[1]) == 1; });
  const Eigen::VectorXd v_fixed = CriticalMode(J, mask, &out.critical_mode_residual);
  const HarmonicSolution mode = Unpacked(probe, basis, v_fixed, embedded.variables());

  ParameterizedResidual f(problem.parameter, build, ns.parameter, basis, sampling, problem.only_frequencies_change);
  CollocationResidual* r = f.At(ns.parameter);
  const std::vector<double> zero(2, 0.0);
  const Eigen::VectorXd x_ns = r->Pack(embedded.coefficients(), embedded.frequencies());
  Eigen::VectorXd v = r->Pack(mode.coefficients(), zero);
  v.normalize();
  const double epsilon = torus_options.amplitude * embedded.coefficients().norm();
  TorusCorrector corrector(&f, PhaseConditionRow(*r, mode.WithFrequencies(embedded.frequencies()), 1), v, x_ns,
                           epsilon);
  Eigen::VectorXd y(f.n() + 1);
  y << x_ns + epsilon * v, ns.parameter;
  SolverOptions solver = options.harmonic_balance.solver;
  solver.method = SolverMethod::kNewton;
  solver.max_iterations = torus_options.max_iterations;
  const SolverSummary report = SolveNonlinear(corrector, &y, solver);
  out.iterations = report.iterations;
  out.seconds = std::chrono::duration<double>(Clock::now() - clock).count();
  if (!report.converged()) {
    out.message = "the torus corrector did not converge: " + report.message;
    return out;
  }
  out.parameter = y(f.n());
  CollocationResidual* final_residual = f.At(out.parameter);
  out.torus = Unpacked(*final_residual, basis, y.head(f.n()), embedded.variables());
  final_residual->Evaluate(y.head(f.n()), &F, nullptr);
  out.residual = F.lpNorm<Eigen::Infinity>();
  const Eigen::MatrixXd& c = out.torus->coefficients();
  double tail = 0;
  for (int j = 0; j < c.rows(); ++j) {
    double sum = 0, outer = 0;
    for (int i = 1; i < basis.size(); ++i) {
      const int l = std::abs(basis.harmonic(i)[1]);
      if (l != 0) sum += c.middleCols(CosColumn(i), 2).row(j).squaredNorm();
      if (l == torus_options.order_new) outer += c.middleCols(CosColumn(i), 2).row(j).squaredNorm();
    }
    out.theta2_amplitude = std::max(out.theta2_amplitude, std::sqrt(sum));
    tail = std::max(tail, std::sqrt(outer));
  }
  out.theta2_tail = out.theta2_amplitude > 0 ? tail / out.theta2_amplitude : 0;
  // The periodic orbit's stability on the torus' side of the NS point.
  const int side = ns.point + ((out.parameter - ns.parameter) * (at.tangent_parameter) >= 0 ? 1 : -1);
  out.periodic_side = side >= 0 && side < static_cast<int>(branch.points.size())
                          ? ToString(branch.points[side].stability)
                          : "unknown";
  out.problem = f.ProblemAt(out.parameter);
  out.sampling = sampling;
  out.phase_reference = mode.WithFrequencies(out.torus->frequencies());
  out.solved = true;
  out.message = "solved";
  return out;
}

}  // namespace rmhb
