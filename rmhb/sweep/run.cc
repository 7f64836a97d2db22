#include "rmhb/sweep/run.h"

#include <chrono>
#include <optional>
#include <stdexcept>

namespace rmhb::sweep {
namespace {

// The journaled point as a continuation start, with the basis and variables
// of the problem at its values (the same at every point of a sweep).
PointResult Restore(const SweepModel& model, const SweepOptions& options, const nlohmann::json& j) {
  if (j.at("solutions").empty()) return PointFromJson(j, HarmonicBasis::Periodic(1), {});
  const HarmonicBalanceProblem problem = model.build(j.at("values").get<std::vector<double>>());
  const HarmonicBasis basis = MakeBasis(static_cast<int>(problem.frequencies.size()), options.solve);
  return PointFromJson(j, basis, problem.system.variables());
}

}  // namespace

std::vector<long> LinesToDo(const ParameterGrid& grid, const std::map<long, nlohmann::json>& done) {
  std::vector<long> lines;
  for (long line = 0; line < grid.num_lines(); ++line)
    for (int i = 0; i < grid.line_length(); ++i)
      if (!done.count(grid.FirstPointOf(line) + i)) {
        lines.push_back(line);
        break;
      }
  return lines;
}

RunStats RunLines(const SweepModel& model, const ParameterGrid& grid, const SweepOptions& options,
                  const LineSource& next, const std::map<long, nlohmann::json>& done, JournalWriter* journal,
                  const std::function<void(const PointResult&)>& on_point) {
  const auto begin = std::chrono::steady_clock::now();
  RunStats stats;
  for (long line = next(); line >= 0; line = next()) {
    std::optional<PointResult> previous;
    const long first = grid.FirstPointOf(line);
    for (long index = first; index < first + grid.line_length(); ++index) {
      const auto journaled = done.find(index);
      if (journaled != done.end()) {
        ++stats.resumed;
        // Restored only when the next point needs it as a start.
        const bool next_missing = index + 1 < first + grid.line_length() && !done.count(index + 1);
        previous.reset();
        if (next_missing) previous = Restore(model, options, journaled->second);
        continue;
      }
      PointResult result = SolvePoint(model, grid, index, previous ? &*previous : nullptr, options);
      journal->Append(PointToJson(result));
      ++stats.solved;
      if (on_point) on_point(result);
      previous = std::move(result);
    }
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return stats;
}

std::vector<nlohmann::json> CollectPoints(const ParameterGrid& grid, const JournalContents& contents) {
  std::vector<nlohmann::json> points;
  for (long index = 0; index < grid.size(); ++index) {
    const auto it = contents.points.find(index);
    if (it == contents.points.end())
      throw std::runtime_error("the journal has no result for point " + std::to_string(index));
    points.push_back(it->second);
  }
  return points;
}

}  // namespace rmhb::sweep
