#include "rmhb/sweep/grid_sweep.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "rmhb/sweep/mpi.h"
#include "rmhb/sweep/run.h"

namespace rmhb::sweep {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

SweepModel MakeSweepModel(const Model& base, const HarmonicSolution& guess, const ParameterGrid& grid) {
  SweepModel model;
  model.build = [&base, &grid](const std::vector<double>& values) {
    return WithParameters(base, AtValues(grid, values)).problem;
  };
  if (base.guess)
    model.guess = [guess](const HarmonicBalanceProblem& problem, int) { return guess.WithFrequencies(problem.frequencies); };
  return model;
}

std::string Fingerprint(const SweepFileInfo& info) {
  const std::string all = info.software + "\n" + info.model + "\n" + info.model_text + "\n" + info.parameters +
                          "\n" + info.options + "\n";
  std::ostringstream hex;
  hex << std::hex << std::hash<std::string>{}(all) << '-' << all.size();
  return hex.str();
}

// One line per solved point, appended with one write(2) so that the lines
// of concurrent ranks never interleave.
void LogPoint(int fd, int rank, const PointResult& p) {
  if (fd < 0) return;
  std::ostringstream line;
  line << "point " << p.index << " rank " << rank << " " << ToString(p.status) << " solutions "
       << p.solutions.size() << " solves " << p.solves << " seconds " << p.seconds << "\n";
  const std::string text = line.str();
  if (::write(fd, text.data(), text.size()) < 0) std::perror("rmhb sweep: --log");
}

double PeakMemoryMib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // kilobytes on Linux
}

// Every rank: solve its share of the lines, journaled.
void SolveLines(const SweepModel& model, const ParameterGrid& grid, const GridSweepOptions& o,
                const std::string& journal_dir, int rank, int ranks, GridSweepSummary* s) {
  const JournalContents done = ReadJournals(journal_dir, o.info.fingerprint);
  const std::vector<long> lines = LinesToDo(grid, done.points);
  RunStats run;
  if (ranks > 1 && rank == 0) {
    ServeLines(lines, ranks);
  } else {
    JournalWriter journal(journal_dir, rank, o.info.fingerprint);
    const int log = o.log.empty() ? -1 : ::open(o.log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (!o.log.empty() && log < 0) throw std::invalid_argument("--log: cannot open '" + o.log + "'");
    std::size_t next = 0;
    const LineSource source =
        ranks > 1 ? RequestLines() : LineSource([&] { return next < lines.size() ? lines[next++] : -1L; });
    run = RunLines(model, grid, o.sweep, source, done.points, &journal,
                   [&](const PointResult& p) { LogPoint(log, rank, p); });
    if (log >= 0) ::close(log);
  }
  s->computed = SumToRoot(run.solved);
  s->resumed = static_cast<long>(done.points.size());
  s->peak_memory_mib = MaxToRoot(PeakMemoryMib());
}

void CountPoints(GridSweepSummary* s) {
  for (const json& p : s->point_records) {
    const std::string status = p.at("status");
    (status == "solved" ? s->solved : status == "no_solution" ? s->no_solution : s->failed)++;
    s->solutions += static_cast<long>(p.at("solutions").size());
  }
}

}  // namespace

std::map<std::string, double> AtValues(const ParameterGrid& grid, const std::vector<double>& values) {
  std::map<std::string, double> at;
  for (std::size_t i = 0; i < values.size(); ++i) at[grid.axes()[i].name] = values[i];
  return at;
}

std::string GridSweepOptions::IsValid() const {
  if (out.empty()) return "--out: no file named";
  return sweep.IsValid();
}

GridSweepSummary SweepGrid(const Model& base, const HarmonicSolution& guess, const ParameterGrid& grid,
                           const GridSweepOptions& options, int rank, int ranks) {
  if (const std::string error = options.IsValid(); !error.empty()) throw std::invalid_argument(error);
  GridSweepOptions o = options;
  o.info.fingerprint = Fingerprint(o.info) + "-" + std::to_string(grid.size());
  o.info.variables.clear();
  for (const Variable& v : base.problem.system.variables()) o.info.variables.push_back(v.name);
  const std::string journal_dir = o.out + ".journal";
  if (fs::exists(journal_dir) && !o.resume)
    throw std::invalid_argument(journal_dir + " exists (an interrupted sweep): --resume finishes it, or remove it");
  Barrier();  // every rank has looked before any creates it
  const auto begin = std::chrono::steady_clock::now();
  const SweepModel model = MakeSweepModel(base, guess, grid);
  GridSweepSummary s;
  SolveLines(model, grid, o, journal_dir, rank, ranks, &s);
  Barrier();  // every journal is complete
  if (rank != 0) return GridSweepSummary{};

  const JournalContents journal = ReadJournals(journal_dir, o.info.fingerprint);
  s.point_records = CollectPoints(grid, journal);
  const std::string partial = o.out + ".partial";
  WriteSweepFile(partial, grid, o.info, s.point_records);
  fs::rename(partial, o.out);
  if (!o.keep_journal) fs::remove_all(journal_dir);
  s.model = o.info.model;
  s.out = o.out;
  s.axes = grid.axes();
  s.points = grid.size();
  s.lines = grid.num_lines();
  s.duplicates = journal.duplicates;
  s.torn_lines = journal.torn_lines;
  s.ranks = ranks;
  CountPoints(&s);
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  return s;
}

json GridSweepSummary::ToJson() const {
  json axes_json = json::array();
  for (const GridAxis& x : axes) axes_json.push_back({{"name", x.name}, {"from", x.from}, {"to", x.to}, {"count", x.count}});
  const int computing = ranks > 1 ? ranks - 1 : 1;
  const double rate = seconds > 0 ? computed / seconds : 0;
  return {{"command", "sweep"}, {"model", model}, {"grid", axes_json}, {"out", out},
          {"points", points}, {"lines", lines}, {"computed", computed},
          {"resumed", resumed}, {"duplicates", duplicates}, {"torn_lines", torn_lines},
          {"solved", solved}, {"no_solution", no_solution}, {"failed", failed}, {"solutions", solutions},
          {"ranks", ranks}, {"computing_ranks", computing}, {"seconds", seconds},
          {"points_per_second", rate}, {"points_per_second_per_rank", rate / computing},
          {"peak_memory_mib_per_rank", peak_memory_mib}};
}

std::string GridSweepSummary::FullReport() const {
  const json r = ToJson();
  char text[1024];
  std::snprintf(text, sizeof text,
                "sweep of %s: %ld points (%ld lines) -> %s\n"
                "  %ld solved (%ld solutions), %ld with no solution, %ld failed\n"
                "  computed now %ld, from the journal %ld, computed twice %ld\n"
                "  %d rank(s), %d computing: %.2f s, %.1f points/s (%.1f per computing rank), peak %.0f MiB per rank\n",
                model.c_str(), points, lines, out.c_str(), solved, solutions, no_solution, failed, computed, resumed,
                duplicates, ranks, r["computing_ranks"].get<int>(), seconds, r["points_per_second"].get<double>(),
                r["points_per_second_per_rank"].get<double>(), peak_memory_mib);
  return text;
}

}  // namespace rmhb::sweep
