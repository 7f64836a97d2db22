// The sweep's point solver and runner on a model file written for the test
// (tests/sweep/models/hardening.yaml), each solution checked against an
// independent CVODE integration of the original equation.

#include "rmhb/sweep/sweep.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "integrators/floquet.h"
#include "rmhb/model/model_definition.h"
#include "rmhb/model/recast.h"
#include "rmhb/sweep/run.h"

namespace rmhb::sweep {
namespace {

namespace fs = std::filesystem;

const model::ModelDefinition& Hardening() {
  static const model::ModelDefinition m = model::LoadModelFile("tests/sweep/models/hardening.yaml");
  return m;
}

model::ParameterValues At(const std::vector<double>& values) {
  model::ParameterValues p{{"W", values[0]}};
  if (values.size() > 1) p["P"] = values[1];
  return p;
}

SweepModel HardeningModel() {
  SweepModel model;
  model.build = [](const std::vector<double>& values) {
    if (values[0] <= 0) throw std::invalid_argument("W must be > 0");
    return model::Recast(Hardening(), At(values)).problem;
  };
  return model;
}

SweepOptions Options() {
  SweepOptions o;
  o.solve.order = 15;
  o.starts = 6;
  return o;
}

TEST(Sweep, FindsTheThreeCoexistingOrbitsEachATrueOrbitWithItsStability) {
  const ParameterGrid grid({ParseGridAxis("W=1.6:1.6:1")});
  SweepOptions options = Options();
  options.starts = 8;
  const PointResult r = SolvePoint(HardeningModel(), grid, 0, nullptr, options);
  ASSERT_EQ(r.status, PointStatus::kSolved) << r.message;
  ASSERT_EQ(r.solutions.size(), 3u);
  for (std::size_t i = 0; i < r.solutions.size(); ++i) {
    const FoundSolution& f = r.solutions[i];
    if (i > 0) {
      EXPECT_GT(f.amplitude, r.solutions[i - 1].amplitude);
    }
    const model::RecastResult recast = model::Recast(Hardening(), At({1.6}));
    model::OriginalSystem original = *recast.original;
    original.BindFrequencies(f.solution.frequencies());
    const std::vector<double> y0 = original.StateFromSolution(f.solution, 0);
    const integrators::FloquetReport floquet = integrators::FloquetMultipliers(
        {original.dimension, original.rhs}, Eigen::Map<const Eigen::VectorXd>(y0.data(), 2), 0,
        2 * M_PI / f.solution.frequencies()[0]);
    ASSERT_TRUE(floquet.ok) << floquet.message;
    EXPECT_LT(floquet.closure_error, 1e-8) << "solution " << i;
    EXPECT_EQ(f.stability, floquet.stable ? "stable" : "unstable") << "solution " << i;
  }
  EXPECT_EQ(r.solutions[1].stability, "unstable");  // the middle one, between two attractors
}

// Lines in any order, or resumed from a journal part-way through a line,
// give the same points to the last bit.
TEST(Sweep, ResultsDoNotDependOnLineOrderOrOnResuming) {
  const ParameterGrid grid({ParseGridAxis("W=1.2:2.0:6"), ParseGridAxis("P=0.2:0.3:2")});
  const SweepModel model = HardeningModel();
  const fs::path root = fs::temp_directory_path() / ("rmhb-sweep-test-" + std::to_string(::getpid()));
  fs::remove_all(root);
  auto run = [&](const std::string& name, std::vector<long> lines, const std::map<long, nlohmann::json>& done) {
    {
      JournalWriter journal((root / name).string(), 0, "f");
      std::size_t next = 0;
      RunLines(model, grid, Options(), [&] { return next < lines.size() ? lines[next++] : -1L; }, done, &journal);
    }
    JournalContents contents = ReadJournals((root / name).string(), "f");
    for (auto& [index, point] : done) contents.points.emplace(index, point);
    std::vector<nlohmann::json> points = CollectPoints(grid, contents);
    for (nlohmann::json& p : points) p.erase("seconds");
    return points;
  };
  const std::vector<nlohmann::json> forward = run("forward", {0, 1}, {});
  EXPECT_EQ(run("backward", {1, 0}, {}), forward);
  std::map<long, nlohmann::json> part;  // as if killed after point 3 of line 0
  const JournalContents first = ReadJournals((root / "forward").string(), "f");
  for (long i = 0; i < 4; ++i) part[i] = first.points.at(i);
  EXPECT_EQ(LinesToDo(grid, part), (std::vector<long>{0, 1}));
  EXPECT_EQ(run("resumed", {0, 1}, part), forward);
  long upper = 0;
  for (const nlohmann::json& p : forward) upper += p["solutions"].size() > 1;
  EXPECT_GT(upper, 0) << "the grid should cross the bistable band";
  fs::remove_all(root);
}

TEST(Sweep, AFailingPointIsRecordedAndTheLineGoesOn) {
  const ParameterGrid grid({ParseGridAxis("W=-0.5:1.5:3")});
  const SweepOptions options = Options();
  const PointResult bad = SolvePoint(HardeningModel(), grid, 0, nullptr, options);
  EXPECT_EQ(bad.status, PointStatus::kFailed);
  EXPECT_NE(bad.message.find("W must be > 0"), std::string::npos);
  const PointResult next = SolvePoint(HardeningModel(), grid, 1, &bad, options);
  EXPECT_EQ(next.status, PointStatus::kSolved) << next.message;
  EXPECT_THROW(
      {
        SweepOptions o = options;
        o.starts = -1;
        SolvePoint(HardeningModel(), grid, 1, nullptr, o);
      },
      std::invalid_argument);
}

}  // namespace
}  // namespace rmhb::sweep
