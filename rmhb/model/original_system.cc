#include "rmhb/model/original_system.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/symbolic_model.h"
#include "rmhb/model/internal/symbolic_tools.h"

namespace rmhb::model {
namespace {

using GiNaC::ex;

// Solves the m x m system a h = b in place (a row-major, destroyed) by
// Gaussian elimination with partial pivoting. False when singular.
bool SolveDense(int m, double* a, double* b) {
  for (int k = 0; k < m; ++k) {
    int pivot = k;
    double best = std::abs(a[k * m + k]);
    for (int i = k + 1; i < m; ++i)
      if (std::abs(a[i * m + k]) > best) best = std::abs(a[i * m + k]), pivot = i;
    if (!(best > 0) || !std::isfinite(best)) return false;
    if (pivot != k) {
      for (int j = 0; j < m; ++j) std::swap(a[k * m + j], a[pivot * m + j]);
      std::swap(b[k], b[pivot]);
    }
    for (int i = k + 1; i < m; ++i) {
      const double f = a[i * m + k] / a[k * m + k];
      if (f == 0) continue;
      for (int j = k; j < m; ++j) a[i * m + j] -= f * a[k * m + j];
      b[i] -= f * b[k];
    }
  }
  for (int k = m - 1; k >= 0; --k) {
    double s = b[k];
    for (int j = k + 1; j < m; ++j) s -= a[k * m + j] * b[j];
    b[k] = s / a[k * m + k];
  }
  return true;
}

std::function<void(double, const double*, double*)> MakeRhs(
    std::shared_ptr<const CompiledFunction> tape, std::vector<int> orders,
    std::vector<double> frequencies) {
  const int m = static_cast<int>(orders.size());
  int n = 0;
  for (int o : orders) n += o;
  const std::size_t num_in = 1 + n + frequencies.size(), num_out = m * m + m;
  return [tape, orders, frequencies, m, n, num_in, num_out](double t, const double* y, double* ydot) {
    // Per-thread buffers: no allocation after the first call, and several
    // threads may integrate with the same system.
    struct Work {
      std::vector<double> in, out, tape;
    };
    thread_local Work work_buffers;
    Work* work = &work_buffers;
    if (work->in.size() < num_in) work->in.resize(num_in);
    if (work->out.size() < num_out) work->out.resize(num_out);
    double* in = work->in.data();
    in[0] = t;
    for (int i = 0; i < n; ++i) in[1 + i] = y[i];
    for (std::size_t i = 0; i < frequencies.size(); ++i) in[1 + n + i] = frequencies[i];
    tape->Evaluate(in, work->out.data(), &work->tape);
    double* a = work->out.data();
    double* h = a + m * m;
    const bool ok = SolveDense(m, a, h);
    int p = 0;
    for (int v = 0; v < m; ++v) {
      for (int j = 0; j + 1 < orders[v]; ++j) ydot[p + j] = y[p + j + 1];
      ydot[p + orders[v] - 1] = ok ? h[v] : std::numeric_limits<double>::quiet_NaN();
      p += orders[v];
    }
  };
}

// F(t, y, y') of a model with algebraic variables: the chains, then the
// equations with the highest derivatives taken from y'.
std::function<void(double, const double*, const double*, double*)> MakeResidual(
    std::shared_ptr<const CompiledFunction> tape, std::vector<int> orders,
    std::vector<double> frequencies) {
  int n = 0, num_highest = 0;
  for (int o : orders) {
    n += std::max(o, 1);
    num_highest += o > 0;
  }
  const std::size_t num_in = 1 + n + num_highest + frequencies.size();
  return [tape, orders, frequencies, n, num_in](double t, const double* y, const double* yp,
                                                double* residual) {
    thread_local std::vector<double> in, out, work;
    if (in.size() < num_in) in.resize(num_in);
    if (out.size() < orders.size()) out.resize(orders.size());
    in[0] = t;
    for (int i = 0; i < n; ++i) in[1 + i] = y[i];
    std::size_t k = 1 + n;
    int p = 0, row = 0;
    for (int o : orders) {
      if (o > 0) in[k++] = yp[p + o - 1];
      for (int j = 0; j + 1 < o; ++j) residual[row++] = yp[p + j] - y[p + j + 1];
      p += std::max(o, 1);
    }
    for (double w : frequencies) in[k++] = w;
    tape->Evaluate(in.data(), out.data(), &work);
    for (std::size_t i = 0; i < orders.size(); ++i) residual[row + i] = out[i];
  };
}

}  // namespace

std::vector<double> OriginalSystem::StateFromSolution(const HarmonicSolution& solution,
                                                      double t) const {
  if (static_cast<int>(sources.size()) != dimension)
    throw std::invalid_argument("OriginalSystem: no mapping from the recast solution");
  std::vector<double> y(dimension);
  for (int i = 0; i < dimension; ++i)
    y[i] = sources[i].derivative ? solution.Derivative(sources[i].variable, t)
                                 : solution.Value(sources[i].variable, t);
  return y;
}

void OriginalSystem::BindFrequencies(const std::vector<double>& w) {
  if (w.size() != frequencies.size())
    throw std::invalid_argument("OriginalSystem::BindFrequencies: one value per base expected");
  frequencies = w;
  if (is_dae()) residual = MakeResidual(equations, orders, frequencies);
  else rhs = MakeRhs(mass_and_rhs, orders, frequencies);
}

OriginalSystem BuildOriginalSystem(const ModelDefinition& model, const ParameterValues& overrides,
                                   const std::vector<double>& frequencies) {
  if (!model.symbolic) throw ModelError("the model was not parsed", {model.source, 0, 0});
  const internal::SymbolicModel& s = *model.symbolic;
  if (static_cast<int>(frequencies.size()) != model.num_bases())
    throw ModelError("BuildOriginalSystem: one frequency per base expected", {model.source, 0, 0});
  const ParameterValues values = model.ParameterValuesWith(overrides);
  const GiNaC::exmap params = internal::ParameterSubstitution(s, values);
  const int m = static_cast<int>(model.variables.size());

  OriginalSystem sys;
  sys.frequencies = frequencies;
  sys.orders = model.orders;
  std::vector<ex> inputs{s.t};
  std::vector<ex> highest;
  bool any_differential = false;
  for (int v = 0; v < m; ++v) {
    const int order = model.orders[v];
    any_differential = any_differential || order > 0;
    for (int j = 0; j < std::max(order, 1); ++j) {
      inputs.push_back(s.derivatives[v][j]);
      sys.state_names.push_back(model.variables[v] + std::string(j, '\''));
      sys.differential.push_back(order > 0);
    }
    if (order > 0) highest.push_back(s.derivatives[v][order]);
  }
  sys.dimension = static_cast<int>(sys.state_names.size());
  if (!any_differential)
    throw ModelError("no variable has a derivative: the equations are purely algebraic",
                     {model.source, 0, 0});
  if (static_cast<int>(highest.size()) < m) {
    // Algebraic variables: the DAE as written, for IDA.
    inputs.insert(inputs.end(), highest.begin(), highest.end());
    for (const auto& b : s.bases) inputs.push_back(b);
    std::vector<ex> residuals;
    for (int i = 0; i < m; ++i) {
      try {
        residuals.push_back(s.equations[i].subs(params, GiNaC::subs_options::no_pattern));
      } catch (const std::exception& err) {
        throw ModelError(std::string("cannot build the original system: ") + err.what() +
                             " in equation " + std::to_string(i + 1),
                         model.equations[i].where);
      }
    }
    try {
      sys.equations = std::make_shared<const CompiledFunction>(internal::Compile(residuals, inputs));
    } catch (const std::exception& err) {
      throw ModelError(std::string("cannot compile the original equations: ") + err.what(),
                       {model.source, 0, 0});
    }
    sys.residual = MakeResidual(sys.equations, sys.orders, sys.frequencies);
    return sys;
  }
  for (const auto& b : s.bases) inputs.push_back(b);

  std::vector<ex> mass, rhs;
  GiNaC::exmap zero;
  for (const ex& h : highest) zero[h] = 0;
  for (int i = 0; i < m; ++i) {
    const SourceLocation& where = model.equations[i].where;
    ex e;
    try {
      e = s.equations[i].subs(params, GiNaC::subs_options::no_pattern);
      for (int j = 0; j < m; ++j) {
        const ex c = e.diff(GiNaC::ex_to<GiNaC::symbol>(highest[j]));
        for (const ex& h : highest)
          if (c.has(h))
            throw ModelError("the highest derivatives appear nonlinearly in equation " +
                                 std::to_string(i + 1) +
                                 ": the integrators need them linearly (M(y) y_high = b(t, y))",
                             where);
        mass.push_back(c);
      }
      rhs.push_back(-e.subs(zero, GiNaC::subs_options::no_pattern));
    } catch (const ModelError&) {
      throw;
    } catch (const std::exception& err) {
      throw ModelError(std::string("cannot build the original system: ") + err.what() +
                           " in equation " + std::to_string(i + 1),
                       where);
    }
  }
  std::vector<ex> outputs = mass;
  outputs.insert(outputs.end(), rhs.begin(), rhs.end());
  try {
    sys.mass_and_rhs =
        std::make_shared<const CompiledFunction>(internal::Compile(outputs, inputs));
  } catch (const std::exception& err) {
    throw ModelError(std::string("cannot compile the original equations: ") + err.what(),
                     {model.source, 0, 0});
  }
  sys.rhs = MakeRhs(sys.mass_and_rhs, sys.orders, sys.frequencies);
  return sys;
}

}  // namespace rmhb::model
