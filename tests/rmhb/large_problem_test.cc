// The large-problem linear algebra (METHOD.md s.17): the Jacobian-vector
// product and the sparse Jacobian against the dense Jacobian, Newton with
// the sparse and Krylov linear solvers against the dense one, and the
// automatic choice.

#include <gtest/gtest.h>

#include <random>

#include "examples/example_system.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/harmonic_balance.h"
#include "rmhb/hill_stability.h"

namespace rmhb {
namespace {

// A residual at order N about a perturbed guess, as the solver sees it.
struct Case {
  examples::ExampleSetup e;
  HarmonicBasis basis;
  std::unique_ptr<CollocationResidual> residual;
  Eigen::VectorXd x;
};

Case MakeCase(const std::string& example, int order, bool condense, bool odd_symmetry = false) {
  Case c{examples::BuildExample(example), HarmonicBasis::Periodic(1), nullptr, {}};
  if (odd_symmetry) c.e.problem.symmetries = {HalfTurnSymmetry{{1}, {-1, -1}, "odd"}};
  const int d = static_cast<int>(c.e.problem.frequencies.size());
  HarmonicBalanceOptions o;
  o.order = order;
  c.basis = MakeBasis(d, o);
  const std::vector<int> m = SamplesForRule(c.e.problem.system, c.basis, SamplingRule::kRhb);
  const Sampling sampling = d == 1 ? Sampling::Uniform(m[0]) : Sampling::Torus(m);
  c.residual = std::make_unique<CollocationResidual>(c.e.problem, c.basis, sampling, condense);
  const HarmonicSolution g = c.e.guess.OnBasis(c.basis);
  c.x = c.residual->Pack(g.coefficients(), g.frequencies());
  std::mt19937 gen(11);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (int i = 0; i < c.x.size(); ++i) c.x(i) += u(gen);
  return c;
}

// J v by products and the sparse J against the dense J, relative to |J|.
void CheckLinearization(const std::string& example, int order, bool condense, bool odd = false) {
  SCOPED_TRACE(example + (condense ? " condensed" : "") + (odd ? " odd" : ""));
  Case c = MakeCase(example, order, condense, odd);
  CollocationResidual& r = *c.residual;
  Eigen::VectorXd F, F_linearized, product;
  Eigen::MatrixXd J;
  ASSERT_TRUE(r.Evaluate(c.x, &F, &J));
  ASSERT_TRUE(r.Linearize(c.x, &F_linearized));
  EXPECT_EQ((F - F_linearized).cwiseAbs().maxCoeff(), 0);
  const double scale = J.cwiseAbs().maxCoeff();
  std::mt19937 gen(3);
  std::normal_distribution<double> normal;
  Eigen::VectorXd v(r.num_unknowns());
  for (int i = 0; i < v.size(); ++i) v(i) = normal(gen);
  // An Evaluate elsewhere must not disturb the kept linearisation.
  Eigen::VectorXd elsewhere;
  r.Evaluate(c.x + 0.1 * v, &elsewhere, nullptr);
  r.ApplyJacobian(v, &product);
  const Eigen::VectorXd dense = J * v;
  EXPECT_LT((product - dense).cwiseAbs().maxCoeff(), 1e-13 * scale * v.cwiseAbs().sum());
  Eigen::SparseMatrix<double> S;
  r.SparseJacobian(1.0, &S);
  EXPECT_LT((Eigen::MatrixXd(S) - J).cwiseAbs().maxCoeff(), 1e-13 * scale);
  // Coarsened: the coupled block and the diagonal blocks are J's own.
  r.SparseJacobian(0.25, &S);
  const Eigen::MatrixXd coarse(S);
  for (int k = 0; k < S.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(S, k); it; ++it)
      EXPECT_NEAR(it.value(), J(it.row(), it.col()), 1e-13 * scale);
  EXPECT_LT(S.nonZeros(), (J.array() != 0).count());
}

TEST(LargeProblem, JacobianProductAndSparseJacobianEqualTheDenseJacobian) {
  for (bool condense : {false, true}) {
    CheckLinearization("duffing", 12, condense);
    CheckLinearization("vanderpol", 15, condense);
    CheckLinearization("pendulum", 9, condense);
    CheckLinearization("relativistic", 8, condense);
    CheckLinearization("rayleigh-plesset", 8, condense);
  }
  CheckLinearization("duffing", 12, true, true);
  CheckLinearization("duffing-2tone", 4, true);
}

// The matrix-free path forms nothing of size (2N + 1)^2: at N = 100 000 (the
// largest order a basis takes) one dense block would take 320 GB, yet the
// residual, its linearisation and a product (against central differences of
// the residual) cost a few FFTs.
TEST(LargeProblem, ProductsAtAnOrderWhoseDenseBlockCouldNotExist) {
  Case c = MakeCase("duffing", 100000, true);
  CollocationResidual& r = *c.residual;
  // At the guess itself (the random perturbation of every one of the 200 001
  // coefficients would make |F| ~ 1e8 and the differences mere round-off).
  const HarmonicSolution guess = c.e.guess.OnBasis(c.basis);
  c.x = r.Pack(guess.coefficients(), guess.frequencies());
  Eigen::VectorXd F, product, plus, minus;
  ASSERT_TRUE(r.Linearize(c.x, &F));
  Eigen::VectorXd v = Eigen::VectorXd::Zero(r.num_unknowns());
  for (int i = 0; i < std::min<int>(40, v.size()); ++i) v(i) = 1.0 / (1 + i);
  r.ApplyJacobian(v, &product);
  const double h = 1e-6;
  ASSERT_TRUE(r.Evaluate(c.x + h * v, &plus, nullptr));
  ASSERT_TRUE(r.Evaluate(c.x - h * v, &minus, nullptr));
  const Eigen::VectorXd difference = (plus - minus) / (2 * h);
  EXPECT_LT((product - difference).cwiseAbs().maxCoeff(), 1e-7 * difference.cwiseAbs().maxCoeff());
}

HarmonicBalanceSummary SolveWith(const std::string& example, int order, LinearSolver solver,
                                 std::map<std::string, double> parameters = {}) {
  examples::ExampleSetup e = examples::BuildExample(example, parameters);
  HarmonicBalanceOptions o;
  o.order = order;
  o.solver.linear_solver = solver;
  return SolveHarmonicBalance(e.problem, e.guess, o);
}

// The same Newton iterates to round-off: the solutions agree to 1e-12.
TEST(LargeProblem, SparseAndKrylovSolvesEqualTheDenseSolve) {
  for (const char* example : {"vanderpol", "duffing", "rayleigh-plesset"}) {
    SCOPED_TRACE(example);
    const HarmonicBalanceSummary dense = SolveWith(example, 40, LinearSolver::kDense);
    ASSERT_TRUE(dense.converged()) << dense.FullReport();
    EXPECT_EQ(dense.solver.linear_solver, LinearSolver::kDense);
    for (LinearSolver solver : {LinearSolver::kSparse, LinearSolver::kKrylov}) {
      const HarmonicBalanceSummary s = SolveWith(example, 40, solver);
      ASSERT_TRUE(s.converged()) << s.FullReport();
      EXPECT_EQ(s.solver.linear_solver, solver);
      EXPECT_LT(SolutionDifference(*s.solution, *dense.solution), 1e-12) << ToString(solver);
      if (solver == LinearSolver::kKrylov) {
        EXPECT_GT(s.solver.linear_iterations, 0);
      }
      EXPECT_GT(s.solver.peak_memory_bytes, 0);
    }
  }
}

TEST(LargeProblem, AutomaticChoiceBySizeAndStructure) {
  Case small = MakeCase("vanderpol", 20, true);
  SolverOptions o;
  EXPECT_EQ(ChooseLinearSolver(*small.residual, o), LinearSolver::kDense);
  // Van der Pol condensed: one equation on one variable, dense coupling.
  EXPECT_EQ(small.residual->JacobianDensity(), 1.0);
  o.dense_limit = 10;
  EXPECT_EQ(ChooseLinearSolver(*small.residual, o), LinearSolver::kKrylov);
  // The fallback's structure test: Duffing not condensed is x' = v (x, v)
  // and v' + ... (v, x): every block; a chain is tested in the pipeline.
  EXPECT_EQ(MakeCase("duffing", 20, false).residual->JacobianDensity(), 1.0);
  o.linear_solver = LinearSolver::kSparse;
  EXPECT_EQ(ChooseLinearSolver(*small.residual, o), LinearSolver::kSparse);
  // The conservative pendulum is overdetermined by one: dense whatever the size.
  Case pendulum = MakeCase("pendulum", 20, true);
  ASSERT_GT(pendulum.residual->num_residuals(), pendulum.residual->num_unknowns());
  SolverOptions tiny;
  tiny.dense_limit = 1;
  EXPECT_EQ(ChooseLinearSolver(*pendulum.residual, tiny), LinearSolver::kDense);
  // Asked for anyway: a status that says why, not a wrong answer.
  Eigen::VectorXd x = pendulum.x;
  tiny.linear_solver = LinearSolver::kKrylov;
  const SolverSummary s = SolveNonlinear(*pendulum.residual, &x, tiny);
  EXPECT_EQ(s.status, SolverStatus::kInvalidInput);
  EXPECT_NE(s.message.find("square"), std::string::npos) << s.message;
  EXPECT_THROW(ParseLinearSolver("lu"), std::invalid_argument);
  EXPECT_EQ(ParseLinearSolver("krylov"), LinearSolver::kKrylov);
}

}  // namespace
}  // namespace rmhb

namespace rmhb {
namespace {

// Hill's exponents by shift-invert Arnoldi (Spectra) equal the dense QZ's:
// a forced Duffing (stable, two exponents), Van der Pol (autonomous: the
// trivial exponent) and the Rayleigh-Plesset bubble, where the harmonic
// centroid has to pick the physical copies among the nearest eigenvalues.
TEST(LargeProblem, ShiftInvertHillExponentsEqualTheDenseQz) {
  for (const char* example : {"duffing", "vanderpol", "rayleigh-plesset"}) {
    SCOPED_TRACE(example);
    examples::ExampleSetup e = examples::BuildExample(example);
    HarmonicBalanceOptions o;
    o.order = 20;
    const HarmonicBalanceSummary s = SolveHarmonicBalance(e.problem, e.guess, o);
    ASSERT_TRUE(s.usable()) << s.FullReport();
    HillOptions dense, shift_invert;
    dense.eigensolver = HillEigensolver::kDense;
    shift_invert.eigensolver = HillEigensolver::kShiftInvert;
    const HillStabilityReport a = HillStability(e.problem, *s.solution, dense);
    const HillStabilityReport b = HillStability(e.problem, *s.solution, shift_invert);
    EXPECT_EQ(b.eigensolver, HillEigensolver::kShiftInvert);
    ASSERT_EQ(a.exponents.size(), b.exponents.size());
    EXPECT_LT(b.eigenvalues, a.eigenvalues);  // only some near the axis
    EXPECT_EQ(a.stable, b.stable);
    EXPECT_EQ(a.trivial, b.trivial);
    // Multipliers: the copy kept may differ by i m w, exp(lambda T) not;
    // a conjugate pair may come in either order.
    for (const auto& mu : a.multipliers) {
      double nearest = INFINITY;
      for (const auto& nu : b.multipliers) nearest = std::min(nearest, std::abs(mu - nu));
      EXPECT_LT(nearest, 1e-9 * (1 + std::abs(mu))) << mu;
    }
    EXPECT_NEAR(a.max_real_part, b.max_real_part, 1e-9);
    HillOptions automatic;
    automatic.dense_limit = 10;
    EXPECT_EQ(HillStability(e.problem, *s.solution, automatic).eigensolver, HillEigensolver::kShiftInvert);
  }
}

}  // namespace
}  // namespace rmhb
