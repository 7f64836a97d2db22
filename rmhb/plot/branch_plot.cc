#include "rmhb/plot/branch_plot.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "rmhb/plot/plot.h"
#include "rmhb/pipeline/branch.h"

namespace rmhb::plot {
namespace {

struct StabilityStyle {
  const char* name;
  int dash;
  const char* color;
};
constexpr StabilityStyle kStyles[] = {
    {"stable", 1, "#1f77b4"}, {"unstable", 2, "#d62728"}, {"neutral", 3, "#7f7f7f"}, {"unknown", 3, "#7f7f7f"}};

const StabilityStyle& StyleOf(const std::string& stability) {
  for (const StabilityStyle& s : kStyles)
    if (stability == s.name) return s;
  return kStyles[3];
}

}  // namespace

std::vector<BranchRow> BranchRows(const ContinuationSummary& summary, const std::string& plot_var) {
  std::vector<BranchRow> rows;
  for (const ContinuationPoint& p : summary.points) {
    BranchRow row{p.parameter, 0, ToString(p.stability), p.fold};
    if (plot_var == "frequency") {
      row.value = p.solution.frequencies()[0];
    } else {
      const int j = plot_var.empty() ? 0 : p.solution.IndexOf(plot_var);
      if (j < 0) {
        std::string names;
        for (const Variable& v : p.solution.variables())
          if (v.role == VariableRole::kState) names += (names.empty() ? "" : ", ") + v.name;
        throw std::invalid_argument("--plot-var: no variable '" + plot_var + "' (variables: " + names +
                                    ", or frequency)");
      }
      row.value = PeakValue(p.solution, j);
    }
    rows.push_back(row);
  }
  return rows;
}

void WriteBranchData(const std::vector<BranchRow>& rows, const std::string& parameter, const std::string& plot_var,
                     const std::string& file) {
  std::ofstream out(file);
  if (!out) throw std::invalid_argument("--plot: cannot write '" + file + "'");
  out.precision(17);
  out << "# " << parameter << " " << (plot_var == "frequency" ? "frequency" : "amplitude") << " stability fold\n";
  for (const BranchRow& r : rows) out << r.parameter << " " << r.value << " " << r.stability << " " << r.fold << "\n";
}

void PlotBranch(const std::vector<BranchRow>& rows, const std::string& title, const std::string& parameter,
                const std::string& plot_var, const std::string& file) {
  const std::string y = plot_var == "frequency" ? "frequency w" : "max |" + plot_var + "(t)|";
  PlotPanel panel{"branch: solid stable, dashed unstable, dotted neutral or unknown", parameter, y, false, false, {}};
  // One series per run of equal stability; neighbours share their end point
  // so the line has no gaps. One legend entry per kind.
  std::vector<std::string> titled;
  for (size_t i = 0; i < rows.size();) {
    size_t j = i;
    while (j + 1 < rows.size() && rows[j + 1].stability == rows[i].stability) ++j;
    const StabilityStyle& style = StyleOf(rows[i].stability);
    PlotSeries s{style.name, {}, {}, PlotSeries::Style::kLines, {}, style.dash, style.color};
    s.in_key = std::find(titled.begin(), titled.end(), style.name) == titled.end();
    if (s.in_key) titled.push_back(style.name);
    for (size_t k = i; k <= std::min(j + 1, rows.size() - 1); ++k) s.x.push_back(rows[k].parameter), s.y.push_back(rows[k].value);
    panel.series.push_back(s);
    i = j + 1;
  }
  PlotSeries folds{"fold", {}, {}, PlotSeries::Style::kPoints, {}, 1, "#000000"};
  for (const BranchRow& r : rows)
    if (r.fold) {
      folds.x.push_back(r.parameter);
      folds.y.push_back(r.value);
      char label[64];
      std::snprintf(label, sizeof label, "fold %s = %.6g", parameter.c_str(), r.parameter);
      folds.labels.push_back(label);
    }
  if (!folds.x.empty()) panel.series.push_back(folds);
  WritePlot({title, {panel}}, file);
}

}  // namespace rmhb::plot
