// Continuation without rebuilding the model (METHOD.md s.19): the recast
// proves on its symbols which parameters enter the problem only as a base
// frequency; a branch in one of them then sets the frequency instead of
// re-recasting the model, and must be the branch the full rebuild gives (to
// the last bit) and the built-in example's with the same equations (to
// round-off). A parameter anywhere else is still rebuilt at every value,
// and every point of its branch must solve the problem built afresh there.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "examples/example_model.h"
#include "examples/example_system.h"
#include "rmhb/collocation_residual.h"
#include "rmhb/model/model_definition.h"
#include "rmhb/model/recast.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/pipeline/monodromy.h"
#include "rmhb/pipeline/settings.h"

namespace rmhb {
namespace {

std::string WriteModel(const std::string& name, const std::string& text) {
  const std::string file = (std::filesystem::temp_directory_path() / ("rmhb-rebuild-" + name + ".yaml")).string();
  std::ofstream(file) << text;
  return file;
}

// The Duffing equations as a user writes them (not the bundled file).
const char* kDuffing = R"yaml(name: my-duffing
variables: [q]
parameters: {damping: 0.1, stiffness: 1, cubic: 1, force: 0.5, w: 0.5}
equations:
  - "q'' + damping*q' + stiffness*q + cubic*q^3 = force*cos(w*t)"
frequencies: [w]
)yaml";

std::map<std::string, int> FrequencyParametersOf(const std::string& equation, const std::string& frequencies,
                                                 const std::string& parameters = "{w: 1.3, c: 0.2}") {
  const std::string text = "variables: [x]\nparameters: " + parameters + "\nequations:\n  - \"" + equation +
                           "\"\nfrequencies: [" + frequencies + "]\n";
  return model::Recast(model::ParseModel(text, "test.yaml")).frequency_parameters;
}

bool SameSystem(const PolynomialSystem& a, const PolynomialSystem& b) {
  if (a.num_equations() != b.num_equations() || a.num_variables() != b.num_variables()) return false;
  for (int i = 0; i < a.num_equations(); ++i) {
    const auto& x = a.equations()[i].lhs.terms();
    const auto& y = b.equations()[i].lhs.terms();
    if (x.size() != y.size()) return false;
    for (auto p = x.begin(), q = y.begin(); p != x.end(); ++p, ++q)
      if (p->first < q->first || q->first < p->first || p->second != q->second) return false;  // exact doubles
  }
  return true;
}

TEST(FrequencyParameters, OnlyABaseFrequencyUsedNowhereElse) {
  const std::map<std::string, int> forcing{{"w", 0}};
  EXPECT_EQ(FrequencyParametersOf("x'' + c*x' + x + x^3 = cos(w*t)", "w"), forcing);
  EXPECT_EQ(FrequencyParametersOf("x'' + c*x' + sin(x) = 0.3*sin(2*w*t + 0.5)", "w"), forcing);
  // In a coefficient too.
  EXPECT_TRUE(FrequencyParametersOf("x'' + w*x' + x = cos(w*t)", "w").empty());
  // In the derivative of a nonlinear function of the forcing (-w sin(w t)).
  EXPECT_TRUE(FrequencyParametersOf("x'' + c*x' + sin(x + cos(w*t)) = 0", "w").empty());
  // A forcing recognised from the value (cos(2 t) is the first harmonic at w = 2 only).
  EXPECT_TRUE(FrequencyParametersOf("x'' + c*x' + x = cos(2*t)", "w", "{w: 2, c: 0.2}").empty());
  // A base that is an expression of the parameter is not bound to it.
  EXPECT_TRUE(FrequencyParametersOf("x'' + c*x' + x = cos(w*t)", "2*W", "{W: 0.7, c: 0.2}").empty());
  // A piecewise-smooth equation evaluated pointwise at explicit time.
  EXPECT_TRUE(FrequencyParametersOf("x'' + c*x' + x + max(x, 0) = cos(w*t)", "w").empty());
  EXPECT_EQ(FrequencyParametersOf("x'' + c*x' + x + max(x, 0) = 0.5 + x^2*0", "w"), forcing);
}

TEST(FrequencyParameters, TheProblemAtAnotherValueDiffersOnlyInThatFrequency) {
  const model::ModelDefinition definition = model::ParseModel(kDuffing, "duffing.yaml");
  const model::RecastResult at = model::Recast(definition);
  ASSERT_EQ(at.frequency_parameters, (std::map<std::string, int>{{"w", 0}}));
  const model::RecastResult there = model::Recast(definition, {{"w", 2.345678901234567}});
  EXPECT_TRUE(SameSystem(at.problem.system, there.problem.system));
  EXPECT_EQ(there.problem.frequencies, std::vector<double>{2.345678901234567});
  EXPECT_EQ(at.problem.conditions.size(), there.problem.conditions.size());
}

// The built-in examples declare theirs (the recast is hand-written): each
// declared parameter changes the problem's frequency and nothing else.
TEST(FrequencyParameters, TheBuiltInExamplesDeclareTheirsTruly) {
  int declared = 0;
  for (const examples::Example& e : examples::AllExamples())
    for (const examples::Parameter& p : e.parameters) {
      if (p.base < 0) continue;
      ++declared;
      const examples::ExampleSetup a = examples::BuildExample(e.name);
      const examples::ExampleSetup b = examples::BuildExample(e.name, {{p.name, 1.37 * p.value}});
      EXPECT_TRUE(SameSystem(a.problem.system, b.problem.system)) << e.name << " " << p.name;
      EXPECT_TRUE(a.problem.conditions.empty() && b.problem.conditions.empty()) << e.name;
      std::vector<double> expected = a.problem.frequencies;
      EXPECT_EQ(expected.at(p.base), p.value) << e.name;
      expected[p.base] = 1.37 * p.value;
      EXPECT_EQ(b.problem.frequencies, expected) << e.name << " " << p.name;
      EXPECT_EQ(examples::ExampleModel(e.name).frequency_parameters.at(p.name), p.base);
    }
  EXPECT_GE(declared, 3);
}

BranchSummary Trace(const Model& model, const std::string& parameter, double from, double to, int order) {
  SolveSettings settings;
  settings.order = order;
  const PreparedSolve p = PrepareSolve(model, settings);
  ContinueOptions options;
  options.parameter = parameter;
  options.from = from;
  options.to = to;
  options.harmonic_balance = p.options;
  return ContinueModel(p.model, p.guess, options);
}

// The largest difference of the parameter and of the user variable's
// coefficients between the points of two branches (at the folds and the
// end only, with `at_fixed_points`: elsewhere a point's place along the
// branch depends on the corrector's last digits through the arclength).
double LargestDifference(const BranchSummary& a, const BranchSummary& b, bool at_fixed_points = false) {
  EXPECT_EQ(a.continuation.points.size(), b.continuation.points.size());
  double largest = 0;
  for (size_t i = 0; i < std::min(a.continuation.points.size(), b.continuation.points.size()); ++i) {
    const ContinuationPoint& p = a.continuation.points[i];
    const ContinuationPoint& q = b.continuation.points[i];
    if (at_fixed_points && !p.fold && i + 1 < a.continuation.points.size()) continue;
    EXPECT_EQ(p.fold, q.fold) << i;
    largest = std::max(largest, std::abs(p.parameter - q.parameter));
    // Variable 0 is the user's variable in both.
    largest = std::max(largest, (p.solution.coefficients().row(0) - q.solution.coefficients().row(0)).cwiseAbs().maxCoeff());
  }
  return largest;
}

// max |F| of `model`'s harmonic balance equations at every point of b.
double LargestResidual(const Model& model, const std::string& parameter, const BranchSummary& b) {
  double largest = 0;
  for (const ContinuationPoint& p : b.continuation.points) {
    const Model here = WithParameters(model, {{parameter, p.parameter}});
    CollocationResidual residual(here.problem, p.solution.basis(), Sampling::Uniform(b.continuation.samples[0]));
    Eigen::VectorXd F;
    EXPECT_TRUE(residual.Evaluate(residual.Pack(p.solution.coefficients(), p.solution.frequencies()), &F, nullptr));
    largest = std::max(largest, F.cwiseAbs().maxCoeff());
  }
  return largest;
}

// Two traces of one branch by different code paths: the same points to
// round-off carried along the arclength.
constexpr double kSameBranch = 1e-9;

TEST(ContinueModel, AFileInItsForcingFrequencyIsTheRebuiltBranchAndTheBuiltInOne) {
  const Model file = LoadModel(WriteModel("duffing", kDuffing));
  EXPECT_TRUE(ModelContinuationProblem(file, "w", 0.5, 3).only_frequencies_change);
  EXPECT_FALSE(ModelContinuationProblem(file, "cubic", 0.5, 3).only_frequencies_change);
  const BranchSummary fast = Trace(file, "w", 0.5, 3, 8);
  ASSERT_EQ(fast.status, BranchStatus::kCompleted) << fast.FullReport();
  ASSERT_EQ(fast.continuation.num_folds, 2) << fast.FullReport();
  // The same file rebuilt at every value, as before.
  Model rebuilt = file;
  rebuilt.frequency_parameters.clear();
  EXPECT_FALSE(ModelContinuationProblem(rebuilt, "w", 0.5, 3).only_frequencies_change);
  // Bit for bit in the Release build; in the sanitizer build (other
  // floating-point contraction of the retuned frequency terms) the points
  // moved along the branch by 9.4e-11.
  EXPECT_LT(LargestDifference(fast, Trace(rebuilt, "w", 0.5, 3, 8)), kSameBranch);
  // The built-in example with the same equations: the same folds and end,
  // and every point of the file's branch solves the built-in's equations.
  const Model example = examples::ExampleModel("duffing", {{"F", 0.5}, {"w", 0.5}});
  const BranchSummary builtin = Trace(example, "w", 0.5, 3, 8);
  EXPECT_LT(LargestDifference(fast, builtin, true), 1e-12);
  EXPECT_LT(LargestResidual(example, "w", fast), 1e-12);
  Model example_rebuilt = example;
  example_rebuilt.frequency_parameters.clear();
  EXPECT_LT(LargestDifference(builtin, Trace(example_rebuilt, "w", 0.5, 3, 8)), kSameBranch);
  EXPECT_LT(LargestDifference(Trace(example, "w", 0.5, 3, 15), Trace(example_rebuilt, "w", 0.5, 3, 15)), kSameBranch);
  EXPECT_LT(LargestDifference(Trace(file, "w", 0.5, 3, 15), Trace(rebuilt, "w", 0.5, 3, 15)), kSameBranch);
}

// Every point of a branch in a rebuilt parameter solves the problem built at
// its value from scratch, and matches a direct solve there.
void ExpectPointsSolveTheirProblem(const Model& model, const std::string& parameter, const BranchSummary& b) {
  ASSERT_EQ(b.status, BranchStatus::kCompleted) << b.FullReport();
  ASSERT_GE(b.continuation.points.size(), 5u);
  const std::vector<ContinuationPoint>& points = b.continuation.points;
  for (size_t i : {size_t(0), points.size() / 2, points.size() - 1}) {
    const ContinuationPoint& p = points[i];
    const Model here = WithParameters(model, {{parameter, p.parameter}});
    HarmonicBalanceOptions o;
    o.order = p.solution.basis().order();
    o.samples = b.continuation.samples;
    const HarmonicBalanceSummary direct = SolveHarmonicBalance(here.problem, GuessAtOrder(here, o.order), o);
    ASSERT_TRUE(direct.converged()) << direct.FullReport();
    EXPECT_LT((direct.solution->coefficients().row(0) - p.solution.coefficients().row(0)).cwiseAbs().maxCoeff(),
              1e-10)
        << parameter << " = " << p.parameter;
  }
}

TEST(ContinueModel, AParameterInANonlinearTermIsRebuiltAndEveryPointIsRight) {
  const Model model = LoadModel(WriteModel("nonlinear", R"yaml(name: soft
variables: [x]
parameters: {a: 0.2, p: 0.8, w: 0.6}
equations:
  - "x'' + 0.3*x' + x + a*x^3 + 0.2*sin(p*x) = 0.4*cos(w*t)"
frequencies: [w]
guess: {x: "0.5*cos(w*t)"}
)yaml"));
  EXPECT_EQ(model.frequency_parameters, (std::map<std::string, int>{{"w", 0}}));
  const BranchSummary in_a = Trace(model, "a", 0.2, 1.0, 8);
  ExpectPointsSolveTheirProblem(model, "a", in_a);
  ExpectPointsSolveTheirProblem(model, "p", Trace(model, "p", 0.8, 2.0, 8));
  // The corrector rebuilds the problem alone (model::Recast's problem_only):
  // the branch the whole model's rebuilds give.
  ASSERT_TRUE(model.reload_problem);
  Model whole = model;
  whole.reload_problem = nullptr;
  EXPECT_LT(LargestDifference(in_a, Trace(whole, "a", 0.2, 1.0, 8)), kSameBranch);
  const HarmonicBalanceProblem alone = ProblemWithParameters(model, {{"a", 0.7}});
  EXPECT_TRUE(SameSystem(alone.system, WithParameters(model, {{"a", 0.7}}).problem.system));
  EXPECT_TRUE(alone.definitions);
}

}  // namespace
}  // namespace rmhb
