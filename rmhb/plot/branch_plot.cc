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

std::vector<BranchRow> BranchRows(const ContinuationSummary& summary, const std::string& plot_var, int branch) {
  std::vector<BranchRow> rows;
  for (const ContinuationPoint& p : summary.points) {
    BranchRow row{p.parameter, 0, ToString(p.stability), p.fold};
    row.branch = branch;
    if (p.fold) row.mark = "fold";
    else if (p.bifurcation >= 0) row.mark = ShortName(summary.bifurcations[p.bifurcation].type);
    if (plot_var == "frequency") {
      row.value = p.solution.frequencies()[0];
    } else if (plot_var == "ratio") {
      const auto& w = p.solution.frequencies();
      if (w.size() != 2) throw std::invalid_argument("--plot-var ratio: w2/w1 needs a branch of tori (two bases)");
      row.value = w[1] / w[0];
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

std::vector<BranchRow> LockedRows(const ContinuationSummary& locked, double ratio, int branch) {
  std::vector<BranchRow> rows = BranchRows(locked, "frequency", branch);
  for (BranchRow& r : rows) r.value = ratio, r.family = "locked";
  return rows;
}

void WriteBranchData(const std::vector<BranchRow>& rows, const std::string& parameter, const std::string& plot_var,
                     const std::string& file) {
  std::ofstream out(file);
  if (!out) throw std::invalid_argument("--plot: cannot write '" + file + "'");
  out.precision(17);
  out << "# " << parameter << " " << (plot_var == "frequency" || plot_var == "ratio" ? plot_var : "amplitude")
      << " stability fold mark branch\n";
  for (const BranchRow& r : rows)
    out << r.parameter << " " << r.value << " " << r.stability << " " << r.fold << " " << r.mark << " " << r.branch
        << "\n";
}

void PlotBranch(const std::vector<BranchRow>& rows, const std::string& title, const std::string& parameter,
                const std::string& plot_var, const std::string& file) {
  const std::string y = plot_var == "frequency" ? "frequency w"
                        : plot_var == "ratio" ? "rotation number w2/w1"
                                              : "max |" + plot_var + "(t)|";
  PlotPanel panel{"branch: solid stable, dashed unstable, dotted neutral or unknown; period-2T or locked branches in green",
                  parameter, y, false, false, {}};
  // One series per run of equal stability on one branch; neighbours share
  // their end point so the line has no gaps. One legend entry per kind.
  std::vector<std::string> titled;
  for (size_t i = 0; i < rows.size();) {
    size_t j = i;
    while (j + 1 < rows.size() && rows[j + 1].stability == rows[i].stability && rows[j + 1].branch == rows[i].branch) ++j;
    const StabilityStyle& style = StyleOf(rows[i].stability);
    const std::string name = rows[i].branch == 0 ? style.name : rows[i].family + ", " + style.name;
    PlotSeries s{name, {}, {}, PlotSeries::Style::kLines, {}, style.dash, rows[i].branch == 0 ? style.color : "#2ca02c"};
    s.in_key = std::find(titled.begin(), titled.end(), name) == titled.end();
    if (s.in_key) titled.push_back(name);
    const size_t last = j + 1 < rows.size() && rows[j + 1].branch == rows[i].branch ? j + 1 : j;
    for (size_t k = i; k <= last; ++k) s.x.push_back(rows[k].parameter), s.y.push_back(rows[k].value);
    panel.series.push_back(s);
    i = j + 1;
  }
  for (const char* kind : {"fold", "BP", "PD", "NS"}) {
    PlotSeries marks{kind, {}, {}, PlotSeries::Style::kPoints, {}, 1, "#000000"};
    for (const BranchRow& r : rows)
      if (r.mark == kind) {
        marks.x.push_back(r.parameter);
        marks.y.push_back(r.value);
        char label[64];
        std::snprintf(label, sizeof label, "%s %s = %.6g", kind, parameter.c_str(), r.parameter);
        marks.labels.push_back(label);
      }
    if (!marks.x.empty()) panel.series.push_back(marks);
  }
  WritePlot({title, {panel}}, file);
}

}  // namespace rmhb::plot
