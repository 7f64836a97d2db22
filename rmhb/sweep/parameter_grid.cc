#include "rmhb/sweep/parameter_grid.h"

#include <cmath>
#include <cstdlib>
#include <set>
#include <stdexcept>

namespace rmhb::sweep {
namespace {

double ParseNumber(const std::string& field, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(field.c_str(), &end);
  if (field.empty() || *end != '\0' || !std::isfinite(v))
    throw std::invalid_argument("--grid " + text + ": '" + field + "' is not a finite number");
  return v;
}

}  // namespace

double GridAxis::Value(int i) const {
  if (count == 1) return from;
  // Both ends exact: the last point is `to`, not from + (n-1) * step.
  return i == count - 1 ? to : from + (to - from) * i / (count - 1);
}

GridAxis ParseGridAxis(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("--grid expects NAME=a:b:n, got '" + text + "'");
  std::vector<std::string> fields;
  std::string rest = text.substr(eq + 1);
  for (std::size_t start = 0;;) {
    const auto colon = rest.find(':', start);
    fields.push_back(rest.substr(start, colon - start));
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  if (fields.size() != 3)
    throw std::invalid_argument("--grid " + text + ": expected NAME=a:b:n (three fields after '=')");
  GridAxis axis;
  axis.name = text.substr(0, eq);
  axis.from = ParseNumber(fields[0], text);
  axis.to = ParseNumber(fields[1], text);
  const double n = ParseNumber(fields[2], text);
  if (n < 1 || n != std::floor(n) || n > 1e8)
    throw std::invalid_argument("--grid " + text + ": n = '" + fields[2] + "' must be a whole number >= 1");
  axis.count = static_cast<int>(n);
  if (axis.count > 1 && axis.from == axis.to)
    throw std::invalid_argument("--grid " + text + ": a = b with n > 1 repeats one point");
  return axis;
}

ParameterGrid::ParameterGrid(std::vector<GridAxis> axes, long max_points) : axes_(std::move(axes)) {
  if (axes_.empty()) throw std::invalid_argument("a sweep needs at least one --grid axis");
  std::set<std::string> names;
  for (const GridAxis& a : axes_) {
    if (!names.insert(a.name).second)
      throw std::invalid_argument("--grid " + a.name + " is given twice");
    if (a.count < 1) throw std::invalid_argument("--grid " + a.name + ": n must be >= 1");
    if (static_cast<double>(size_) * a.count > static_cast<double>(max_points))
      throw std::invalid_argument("the grid has more than " + std::to_string(max_points) + " points");
    size_ *= a.count;
  }
}

std::vector<int> ParameterGrid::Indices(long point) const {
  if (point < 0 || point >= size_) throw std::out_of_range("grid point index out of range");
  std::vector<int> indices;
  for (const GridAxis& a : axes_) {
    indices.push_back(static_cast<int>(point % a.count));
    point /= a.count;
  }
  return indices;
}

std::vector<double> ParameterGrid::Values(long point) const {
  const std::vector<int> indices = Indices(point);
  std::vector<double> values;
  for (std::size_t i = 0; i < axes_.size(); ++i) values.push_back(axes_[i].Value(indices[i]));
  return values;
}

}  // namespace rmhb::sweep
