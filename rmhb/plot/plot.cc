#include "rmhb/plot/plot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

extern char** environ;

namespace rmhb::plot {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A gnuplot double-quoted string (single quotes are common here: x'').
std::string Quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

// A label in a data file is double-quoted; gnuplot has no escape there.
std::string DataLabel(std::string s) {
  for (char& c : s)
    if (c == '"') c = '\'';
  return s;
}

bool Plottable(double v, bool log) { return std::isfinite(v) && (!log || v > 0); }

// Removes the temporary directory however the plot ends.
struct TempDir {
  std::string path;
  TempDir() {
    const char* base = std::getenv("TMPDIR");
    std::string pattern = std::string(base && *base ? base : "/tmp") + "/rmhb-plot-XXXXXX";
    if (!mkdtemp(pattern.data())) throw std::runtime_error("cannot create a temporary directory for the plot");
    path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

std::string Script(const Plot& plot, const std::string& file, const std::string& dir) {
  std::ostringstream s;
  const int rows = static_cast<int>(plot.panels.size());
  const bool svg = EndsWith(file, ".svg");
  s << "set terminal " << (svg ? "svg" : "pngcairo") << " size 1000," << 80 + 380 * rows
    << " noenhanced font 'sans,11'\n";
  s << "set output " << Quote(file) << "\n";
  s << "set multiplot layout " << rows << ",1 title " << Quote(plot.title) << "\n";
  s << "set grid\nset key outside right top box\nset linetype 5 lc rgb \"black\"\n";
  for (size_t p = 0; p < plot.panels.size(); ++p) {
    const PlotPanel& panel = plot.panels[p];
    s << "set title " << Quote(panel.title) << "\n";
    s << "set xlabel " << Quote(panel.x_label) << "\nset ylabel " << Quote(panel.y_label) << "\n";
    s << (panel.log_x ? "set logscale x\nset format x '%.0e'\n" : "unset logscale x\nset format x '% g'\n");
    s << (panel.log_y ? "set logscale y\nset format y '%.0e'\n" : "unset logscale y\nset format y '% g'\n");
    std::string plots;
    for (size_t k = 0; k < panel.series.size(); ++k) {
      const PlotSeries& series = panel.series[k];
      const std::string data = dir + "/panel" + std::to_string(p) + "_series" + std::to_string(k) + ".dat";
      std::ofstream out(data);
      out.precision(17);
      int points = 0;
      for (size_t i = 0; i < series.x.size() && i < series.y.size(); ++i) {
        if (!Plottable(series.x[i], panel.log_x) || !Plottable(series.y[i], panel.log_y)) continue;
        out << series.x[i] << " " << series.y[i];
        if (i < series.labels.size()) out << " \"" << DataLabel(series.labels[i]) << "\"";
        out << "\n";
        ++points;
      }
      if (points == 0) continue;  // gnuplot refuses an empty data file
      if (!plots.empty()) plots += ", \\\n  ";
      // Line options first, the title last: gnuplot refuses options after it.
      const std::string title = (series.dash != 1 ? " dt " + std::to_string(series.dash) : std::string()) +
                                (series.color.empty() ? "" : " lc rgb " + Quote(series.color)) +
                                (series.in_key ? " title " + Quote(series.title) : std::string(" notitle"));
      switch (series.style) {
        case PlotSeries::Style::kLines: plots += Quote(data) + " using 1:2 with lines lw 2" + title; break;
        case PlotSeries::Style::kLinesPoints: plots += Quote(data) + " using 1:2 with linespoints lw 2 pt 7" + title; break;
        case PlotSeries::Style::kPoints:
          plots += Quote(data) + " using 1:2 with points pt 7 ps 1.5" + title;
          if (!series.labels.empty())
            plots += ", \\\n  " + Quote(data) + " using 1:2:3 with labels offset 0,1 font 'sans,9' notitle";
          break;
        case PlotSeries::Style::kImpulses:
          plots += Quote(data) + " using 1:2 with impulses lw 2" + title;
          if (!series.labels.empty())
            plots += ", \\\n  " + Quote(data) + " using 1:2:3 with labels offset 0,0.8 font 'sans,8' notitle";
          break;
      }
    }
    if (plots.empty()) {
      s << "set label 1 'no finite data' at graph 0.5,0.5 center\nplot 2 notitle\nunset label 1\n";
    } else {
      s << "plot " << plots << "\n";
    }
  }
  s << "unset multiplot\nset output\n";
  return s.str();
}

}  // namespace

std::string FindGnuplot() {
  const char* path = std::getenv("PATH");
  if (!path) return "";
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    const std::string candidate = (dir.empty() ? "." : dir) + "/gnuplot";
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

void CheckPlotRequest(const std::string& file) {
  if (!EndsWith(file, ".png") && !EndsWith(file, ".svg"))
    throw std::invalid_argument("--plot: '" + file + "' must end in .png or .svg");
  if (FindGnuplot().empty()) throw std::invalid_argument("gnuplot not found: install gnuplot-nox (--plot " + file + ")");
}

namespace {

// Runs gnuplot on the script in `dir` (plot.gp), which writes `file`.
void RunGnuplot(const TempDir& dir, const std::string& file) {
  const std::string gnuplot = FindGnuplot();
  const std::string script = dir.path + "/plot.gp", log = dir.path + "/gnuplot.log";

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::string arg0 = "gnuplot", arg1 = script;
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, gnuplot.c_str(), &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) throw std::invalid_argument("cannot run " + gnuplot + " for --plot " + file);
  int status = 0;
  waitpid(pid, &status, 0);
  std::ifstream in(log);
  const std::string messages((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  struct stat st;
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || stat(file.c_str(), &st) != 0 || st.st_size == 0)
    throw std::invalid_argument("gnuplot could not write '" + file + "': " + messages);
}


// The start of a script that draws into `file` (PNG or SVG by extension).
std::string Terminal(const std::string& file) {
  return EndsWith(file, ".svg") ? "set terminal svg size 900,700 dynamic\n"
                                : "set terminal pngcairo size 900,700 noenhanced\n";
}

}  // namespace

void WritePlot(const Plot& plot, const std::string& file) {
  CheckPlotRequest(file);
  TempDir dir;
  std::ofstream(dir.path + "/plot.gp") << Script(plot, file, dir.path);
  RunGnuplot(dir, file);
}

void WriteHeatMap(const HeatMap& map, const std::string& file) {
  CheckPlotRequest(file);
  if (map.z.size() != map.x.size() * map.y.size() || map.x.empty() || map.y.empty())
    throw std::invalid_argument("WriteHeatMap: z needs one value per (x, y)");
  TempDir dir;
  {
    std::ofstream data(dir.path + "/map.dat");
    data.precision(17);
    for (std::size_t j = 0; j < map.y.size(); ++j) {
      for (std::size_t i = 0; i < map.x.size(); ++i) {
        const double z = map.z[i + map.x.size() * j];
        data << map.x[i] << ' ' << map.y[j] << ' ';
        if (std::isfinite(z)) data << z << '\n';
        else data << "NaN\n";
      }
      data << '\n';
    }
  }
  std::ofstream script(dir.path + "/plot.gp");
  script << Terminal(file) << "set output " << Quote(file) << "\n"
         << "set title " << Quote(map.title) << "\nset xlabel " << Quote(map.x_label) << "\nset ylabel "
         << Quote(map.y_label) << "\nset cblabel " << Quote(map.z_label) << "\n"
         << "set view map\nset datafile missing 'NaN'\nset palette rgbformulae 33,13,10\n"
         << "set xrange [*:*] noextend\nset yrange [*:*] noextend\n"
         << "plot " << Quote(dir.path + "/map.dat") << " using 1:2:3 with image notitle\nset output\n";
  script.close();
  RunGnuplot(dir, file);
}

}  // namespace rmhb::plot
