#include "rmhb/cli/sweep_command.h"

#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "rmhb/cli/commands.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "rmhb/sweep/mpi.h"
#include "rmhb/sweep/run.h"
#include "rmhb/sweep/sweep_file.h"
#include "rmhb/version.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
using namespace rmhb::sweep;
namespace fs = std::filesystem;

std::map<std::string, double> AtValues(const ParameterGrid& grid, const std::vector<double>& values) {
  std::map<std::string, double> at;
  for (std::size_t i = 0; i < values.size(); ++i) at[grid.axes()[i].name] = values[i];
  return at;
}

SweepModel MakeSweepModel(const ParameterGrid& grid, const PreparedSolve& prepared) {
  SweepModel model;
  model.build = [&prepared, &grid](const std::vector<double>& values) {
    return WithParameters(prepared.model, AtValues(grid, values)).problem;
  };
  if (prepared.model.guess) {
    const HarmonicSolution guess = prepared.guess;
    model.guess = [guess](const HarmonicBalanceProblem& problem, int) {
      return guess.WithFrequencies(problem.frequencies);
    };
  }
  return model;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// What changes results: the fingerprint ties a journal to its sweep.
json ResultOptions(const SweepArgs& a, const SweepOptions& o) {
  return {{"order", o.solve.order},       {"method", a.settings.solve.method}, {"samples", a.settings.solve.samples},
          {"solver", a.settings.solve.solver},  {"scaling", a.settings.solve.scaling},
          {"max_iterations", a.settings.solve.max_iterations}, {"residual_tol", a.settings.solve.residual_tol},
          {"frequencies", a.settings.solve.frequencies}, {"starts", o.starts}, {"range", a.range},
          {"seed", o.seed},               {"stability", o.stability},   {"cluster_tolerance", o.cluster_tolerance}};
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

struct Totals {
  RunStats run;
  long solved = 0, resumed = 0;
  double peak_mib = 0;
};

// Every rank: solve its share of the lines, journaled.
Totals SolveLines(const SweepArgs& a, const SweepModel& model, const ParameterGrid& grid,
                  const SweepOptions& options, const std::string& journal_dir, const std::string& fingerprint,
                  int rank, int ranks) {
  const JournalContents done = ReadJournals(journal_dir, fingerprint);
  const std::vector<long> lines = LinesToDo(grid, done.points);
  Totals totals;
  if (ranks > 1 && rank == 0) {
    ServeLines(lines, ranks);
  } else {
    JournalWriter journal(journal_dir, rank, fingerprint);
    const int log = a.log.empty() ? -1 : ::open(a.log.c_str(), O_WRONLY | O_CREAT | O_APPEND, 0644);
    if (!a.log.empty() && log < 0) throw std::invalid_argument("--log: cannot open '" + a.log + "'");
    std::size_t next = 0;
    const LineSource source =
        ranks > 1 ? RequestLines() : LineSource([&] { return next < lines.size() ? lines[next++] : -1L; });
    totals.run = RunLines(model, grid, options, source, done.points, &journal,
                          [&](const PointResult& p) { LogPoint(log, rank, p); });
    if (log >= 0) ::close(log);
  }
  totals.solved = SumToRoot(totals.run.solved);
  totals.resumed = static_cast<long>(done.points.size());
  totals.peak_mib = MaxToRoot(PeakMemoryMib());
  return totals;
}

void PlotMap(const SweepArgs& a, const ParameterGrid& grid, const std::vector<json>& points) {
  const auto& axes = grid.axes();
  auto value = [&](const json& p) {
    if (a.plot_value == "count") return static_cast<double>(p.at("solutions").size());
    double peak = NAN;
    for (const json& s : p.at("solutions")) peak = std::isnan(peak) ? s.at("amplitude").get<double>()
                                                                      : std::max(peak, s.at("amplitude").get<double>());
    return peak;
  };
  plot::HeatMap map;
  map.title = a.settings.model + ": " + (a.plot_value == "count" ? "number of solutions" : "largest amplitude");
  map.x_label = axes[0].name;
  map.z_label = a.plot_value;
  for (int i = 0; i < axes[0].count; ++i) map.x.push_back(axes[0].Value(i));
  if (axes.size() == 2) {
    map.y_label = axes[1].name;
    for (int j = 0; j < axes[1].count; ++j) map.y.push_back(axes[1].Value(j));
  } else {
    map.y = {0};
  }
  for (const json& p : points) map.z.push_back(value(p));
  plot::WriteHeatMap(map, a.plot);
}

json Report(const SweepArgs& a, const ParameterGrid& grid, const Totals& t, const JournalContents& journal,
            const std::vector<json>& points, int ranks, double seconds) {
  long solved = 0, none = 0, failed = 0, solutions = 0;
  for (const json& p : points) {
    const std::string status = p.at("status");
    (status == "solved" ? solved : status == "no_solution" ? none : failed)++;
    solutions += static_cast<long>(p.at("solutions").size());
  }
  json axes = json::array();
  for (const GridAxis& x : grid.axes())
    axes.push_back({{"name", x.name}, {"from", x.from}, {"to", x.to}, {"count", x.count}});
  const int computing = ranks > 1 ? ranks - 1 : 1;
  const double rate = seconds > 0 ? t.solved / seconds : 0;
  return {{"command", "sweep"}, {"model", a.settings.model}, {"grid", axes}, {"out", a.out},
          {"points", grid.size()}, {"lines", grid.num_lines()}, {"computed", t.solved},
          {"resumed", t.resumed}, {"duplicates", journal.duplicates}, {"torn_lines", journal.torn_lines},
          {"solved", solved}, {"no_solution", none}, {"failed", failed}, {"solutions", solutions},
          {"ranks", ranks}, {"computing_ranks", computing}, {"seconds", seconds},
          {"points_per_second", rate}, {"points_per_second_per_rank", rate / computing},
          {"peak_memory_mib_per_rank", t.peak_mib}};
}

void PrintReport(const json& r) {
  std::printf("sweep of %s: %ld points (%ld lines) -> %s\n", r["model"].get<std::string>().c_str(),
              r["points"].get<long>(), r["lines"].get<long>(), r["out"].get<std::string>().c_str());
  std::printf("  %ld solved (%ld solutions), %ld with no solution, %ld failed\n", r["solved"].get<long>(),
              r["solutions"].get<long>(), r["no_solution"].get<long>(), r["failed"].get<long>());
  std::printf("  computed now %ld, from the journal %ld, computed twice %ld\n", r["computed"].get<long>(),
              r["resumed"].get<long>(), r["duplicates"].get<long>());
  std::printf("  %d rank(s), %d computing: %.2f s, %.1f points/s (%.1f per computing rank), peak %.0f MiB per rank\n",
              r["ranks"].get<int>(), r["computing_ranks"].get<int>(), r["seconds"].get<double>(),
              r["points_per_second"].get<double>(), r["points_per_second_per_rank"].get<double>(),
              r["peak_memory_mib_per_rank"].get<double>());
}

}  // namespace

void AddSweepOptions(CLI::App* app, SweepArgs* a) {
  AddSolveSettings(app, &a->settings);
  app->add_option("--grid", a->grid,
                  "A parameter axis NAME=a:b:n, n values from a to b (repeatable; the first axis "
                  "runs fastest and is the continuation direction)")
      ->required();
  app->add_option("--starts", a->starts, "Random starts per point, besides continuation (default 8)")
      ->check(CLI::Range(0, 1000000));
  app->add_option("--range", a->range, "Every coefficient of a random start is uniform in lo:hi (default -2:2)");
  app->add_option("--seed", a->seed, "Random seed (default 1); results depend on it, not on the ranks");
  app->add_option("--out", a->out, "The HDF5 result file (default sweep.h5); its journal is OUT.journal/");
  app->add_flag("--resume", a->resume,
                "Finish an interrupted sweep from OUT.journal/ without recomputing finished points");
  app->add_flag("--keep-journal", a->keep_journal, "Keep OUT.journal/ after the file is written");
  app->add_flag("--no-stability", a->no_stability, "Skip Hill's stability verdict per solution");
  app->add_option("--log", a->log, "Append one line per computed point (index, rank, status, time) to FILE");
  app->add_option("--plot", a->plot, "A heat map of the first two axes (PNG or SVG by extension)");
  app->add_option("--plot-value", a->plot_value, "What --plot shows: amplitude (largest, default) or count")
      ->check(CLI::IsMember({"amplitude", "count"}));
  app->add_flag("--json", a->json, "Machine-readable summary");
  app->footer(
      "Over MPI: mpirun -n R rmhb sweep ... (rank 0 hands out grid lines, the others solve them).\n"
      "Exit codes: 0 the file is written (failed points are recorded in it), 1 usage, 2 bad input\n"
      "(unknown parameter, bad --grid, a journal of another sweep, OUT.journal/ exists without\n"
      "--resume), 4 internal.");
}

int RunSweep(const SweepArgs& a, int rank, int ranks) {
  if (a.settings.solve.tol > 0) throw std::invalid_argument("--tol does not apply to sweep: give --order");
  std::vector<GridAxis> axes;
  for (const std::string& text : a.grid) axes.push_back(ParseGridAxis(text));
  const ParameterGrid grid(std::move(axes));
  if (!a.plot.empty()) {
    plot::CheckPlotRequest(a.plot);
    if (grid.axes().size() > 2) throw std::invalid_argument("--plot draws grids of one or two axes");
  }
  const std::vector<double> range = ParseNumberList(a.range, "--range");
  if (range.size() != 2 || !(range[0] < range[1]))
    throw std::invalid_argument("--range expects lo:hi with lo < hi, got '" + a.range + "'");
  const PreparedSolve prepared = Prepare(a.settings, AtValues(grid, grid.Values(0)));
  SweepOptions options;
  options.solve = prepared.options;
  options.starts = a.starts;
  options.low = range[0];
  options.high = range[1];
  options.seed = a.seed;
  options.stability = !a.no_stability;
  if (const std::string error = options.IsValid(); !error.empty()) throw std::invalid_argument(error);

  SweepFileInfo info;
  info.software = "rmhb " RMHB_VERSION_STRING;
  info.model = a.settings.model;
  if (prepared.model.from_file) info.model_text = ReadFile(a.settings.model);
  for (const std::string& s : a.settings.set) info.parameters += (info.parameters.empty() ? "" : " ") + s;
  info.options = ResultOptions(a, options).dump();
  for (const GridAxis& x : grid.axes()) info.options += " " + x.name;
  info.fingerprint = Fingerprint(info) + "-" + std::to_string(grid.size());
  for (const Variable& v : prepared.model.problem.system.variables()) info.variables.push_back(v.name);

  const std::string journal_dir = a.out + ".journal";
  if (fs::exists(journal_dir) && !a.resume)
    throw std::invalid_argument(journal_dir + " exists (an interrupted sweep): --resume finishes it, or remove it");
  Barrier();  // every rank has looked before any creates it
  const auto begin = std::chrono::steady_clock::now();
  const SweepModel model = MakeSweepModel(grid, prepared);
  const Totals totals = SolveLines(a, model, grid, options, journal_dir, info.fingerprint, rank, ranks);
  Barrier();  // every journal is complete
  if (rank != 0) return kExitOk;

  const JournalContents journal = ReadJournals(journal_dir, info.fingerprint);
  const std::vector<json> points = CollectPoints(grid, journal);
  const std::string partial = a.out + ".partial";
  WriteSweepFile(partial, grid, info, points);
  fs::rename(partial, a.out);
  if (!a.keep_journal) fs::remove_all(journal_dir);
  if (!a.plot.empty()) PlotMap(a, grid, points);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  const json report = Report(a, grid, totals, journal, points, ranks, seconds);
  if (a.json)
    std::cout << report.dump(2) << "\n";
  else
    PrintReport(report);
  return kExitOk;
}

}  // namespace rmhb::cli
