#ifndef RMHB_PLOT_PLOT_H_
#define RMHB_PLOT_PLOT_H_

// Figures drawn by gnuplot, PNG or SVG by the file's extension: the data and
// a gnuplot script go to a temporary directory, gnuplot draws, the directory
// is removed. The studies' own pictures (figures.h, branch_plot.h: what
// `--plot FILE` of every command draws) are built on these. gnuplot is a
// run-time dependency only (Debian: gnuplot-nox); without it a plot request
// throws std::invalid_argument saying what to install (the CLI: exit 2), and
// nothing else depends on it.

#include <string>
#include <vector>

namespace rmhb::plot {

struct PlotSeries {
  std::string title;  // legend entry
  std::vector<double> x, y;
  enum class Style { kLines, kLinesPoints, kPoints, kImpulses } style = Style::kLines;
  // With kImpulses or kPoints: a text label drawn above each point (e.g. "(1,-2)").
  std::vector<std::string> labels;
  int dash = 1;       // gnuplot dashtype: 1 solid, 2 dashed, 3 dotted
  std::string color = {};  // e.g. "#1f77b4"; empty: gnuplot's sequence
  bool in_key = true; // false: no legend entry (a later segment of a line already titled)
};

struct PlotPanel {
  std::string title, x_label, y_label;
  bool log_x = false, log_y = false;  // non-positive values are left out
  std::vector<PlotSeries> series;
};

// Panels are stacked top to bottom on one page.
struct Plot {
  std::string title;
  std::vector<PlotPanel> panels;
};

// Where gnuplot is on PATH ("" if not found).
std::string FindGnuplot();

// Checks a --plot request before any work is done: the extension and that
// gnuplot is there. Throws std::invalid_argument as WritePlot does.
void CheckPlotRequest(const std::string& file);

// Draws `plot` into `file`, PNG or SVG by its extension. Throws
// std::invalid_argument when the extension is neither, when gnuplot is not
// found ("gnuplot not found: install gnuplot-nox") or when it fails (with
// its own message).
void WritePlot(const Plot& plot, const std::string& file);

// A heat map of z over a rectangular grid: z[i + x.size() j] at (x[i], y[j]);
// non-finite values are left blank. Throws like WritePlot.
struct HeatMap {
  std::string title, x_label, y_label, z_label;
  std::vector<double> x, y, z;
};
void WriteHeatMap(const HeatMap& map, const std::string& file);

}  // namespace rmhb::plot

#endif  // RMHB_PLOT_PLOT_H_
