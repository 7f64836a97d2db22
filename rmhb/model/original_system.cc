#include "rmhb/model/original_system.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/nonsmooth.h"
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

using SwitchedRhs = std::function<void(double, const double*, const signed char*, double*, double*)>;

// The tape's outputs (BuildOriginalSystem): the mass matrix M (m x m,
// row-major), b0, then per Coulomb term k (K of them) the column c_k of
// its force in the equations, its bound Fn_k, its velocity v_k and the
// gradient of v_k in the n states.
struct Layout {
  int m = 0, n = 0, K = 0;
  std::vector<int> orders;
  int mass() const { return 0; }
  int b0() const { return m * m; }
  int c() const { return m * m + m; }
  int fn() const { return c() + m * K; }
  int v() const { return fn() + K; }
  int dv() const { return v() + K; }
  int size() const { return dv() + K * n; }
};

// y' with the tape's switches on `modes` (null: by their arguments' signs)
// and each Coulomb term sliding (mode +-1: force +-Fn) or stuck (0: the
// force is the multiplier that keeps dv/dt = 0, solved for together with
// the highest derivatives). Writes the switch arguments (tape switches,
// then per Coulomb term v when sliding, Fn - |force| when stuck) and the
// forces when the pointers are not null. False when singular.
bool SwitchedDerivative(const CompiledFunction& tape, const Layout& L, const std::vector<double>& frequencies,
                        double t, const double* y, const signed char* modes, double* ydot, double* arguments,
                        double* forces) {
  struct Work {
    std::vector<double> in, out, tape, a, rhs;
  };
  thread_local Work work;
  work.in.resize(1 + L.n + frequencies.size());
  work.out.resize(L.size());
  double* in = work.in.data();
  in[0] = t;
  for (int i = 0; i < L.n; ++i) in[1 + i] = y[i];
  for (std::size_t i = 0; i < frequencies.size(); ++i) in[1 + L.n + i] = frequencies[i];
  const int S = tape.num_switches();
  tape.Evaluate(in, work.out.data(), &work.tape, modes);
  if (arguments) tape.SwitchArguments(work.tape, arguments);
  const double* out = work.out.data();
  // Unknowns: h (m), then the force of every stuck term.
  std::vector<int> stuck;
  for (int k = 0; k < L.K; ++k) {
    const int mode = modes ? modes[S + k] : (out[L.v() + k] > 0) - (out[L.v() + k] < 0);
    if (mode == 0 && modes) stuck.push_back(k);
  }
  const int u = L.m + static_cast<int>(stuck.size());
  work.a.assign(u * u, 0.0);
  work.rhs.assign(u, 0.0);
  double* a = work.a.data();
  double* r = work.rhs.data();
  for (int i = 0; i < L.m; ++i) {
    for (int j = 0; j < L.m; ++j) a[i * u + j] = out[L.mass() + i * L.m + j];
    r[i] = out[L.b0() + i];
  }
  for (int k = 0; k < L.K; ++k) {
    const auto it = std::find(stuck.begin(), stuck.end(), k);
    if (it != stuck.end()) {
      const int col = L.m + static_cast<int>(it - stuck.begin());
      for (int i = 0; i < L.m; ++i) a[i * u + col] = out[L.c() + k * L.m + i];
      // dv/dt = 0: sum over states of dv/dy_i y_i', the highest ones unknown.
      int p = 0;
      for (int v = 0; v < L.m; ++v) {
        for (int j = 0; j < L.orders[v]; ++j) {
          const double g = out[L.dv() + k * L.n + p + j];
          if (j + 1 < L.orders[v]) r[col] -= g * y[p + j + 1];
          else a[col * u + v] += g;
        }
        p += L.orders[v];
      }
      continue;
    }
    const double v = out[L.v() + k];
    const int mode = modes ? modes[S + k] : (v > 0) - (v < 0);
    for (int i = 0; i < L.m; ++i) r[i] -= out[L.c() + k * L.m + i] * mode * out[L.fn() + k];
    if (forces) forces[k] = mode * out[L.fn() + k];
    if (arguments) arguments[S + k] = v;
  }
  const bool ok = SolveDense(u, a, r);
  for (std::size_t q = 0; q < stuck.size(); ++q) {
    const int k = stuck[q];
    const double force = r[L.m + static_cast<int>(q)];
    if (forces) forces[k] = force;
    if (arguments) arguments[S + k] = out[L.fn() + k] - std::abs(force);
  }
  int p = 0;
  for (int v = 0; v < L.m; ++v) {
    for (int j = 0; j + 1 < L.orders[v]; ++j) ydot[p + j] = y[p + j + 1];
    ydot[p + L.orders[v] - 1] = ok ? r[v] : std::numeric_limits<double>::quiet_NaN();
    p += L.orders[v];
  }
  return ok;
}

SwitchedRhs MakeSwitchedRhs(std::shared_ptr<const CompiledFunction> tape, Layout layout,
                            std::vector<double> frequencies) {
  return [tape, layout, frequencies](double t, const double* y, const signed char* modes, double* ydot,
                                     double* arguments) {
    SwitchedDerivative(*tape, layout, frequencies, t, y, modes, ydot, arguments, nullptr);
  };
}

// A Coulomb term's next mode at a crossing (direction +-1) or at the start
// (0): leaving a stick phase (its force reached the bound) it slides the
// way the force pushes; when its velocity vanishes (or at the start with
// v = 0) it sticks if the force that keeps it stuck is within the bound,
// else slides the way that force pushes. Other switches: the crossing's
// direction (at the start, direction 0: the mode they have).
std::function<int(double, const double*, int, int, const signed char*)> MakeNextMode(
    std::shared_ptr<const CompiledFunction> tape, Layout layout, std::vector<double> frequencies) {
  return [tape, layout, frequencies](double t, const double* y, int k, int direction, const signed char* modes) {
    const int S = tape->num_switches();
    if (k < S) return direction == 0 ? int(modes[k]) : direction > 0 ? 1 : -1;
    std::vector<signed char> trial(modes, modes + S + layout.K);
    std::vector<double> ydot(layout.n), arguments(S + layout.K), forces(layout.K);
    if (direction == 0) {
      SwitchedDerivative(*tape, layout, frequencies, t, y, nullptr, ydot.data(), arguments.data(), nullptr);
      const double v = arguments[k];
      if (v != 0) return v > 0 ? 1 : -1;
    }
    const bool leaving_stick = direction != 0 && modes[k] == 0;
    trial[k] = 0;
    SwitchedDerivative(*tape, layout, frequencies, t, y, trial.data(), ydot.data(), arguments.data(), forces.data());
    const int push = forces[k - S] >= 0 ? 1 : -1;
    if (leaving_stick || arguments[k] < 0) return push;
    return 0;
  };
}

std::function<void(double, const double*, double*)> MakeRhs(std::shared_ptr<const CompiledFunction> tape,
                                                             Layout layout, std::vector<double> frequencies) {
  SwitchedRhs f = MakeSwitchedRhs(std::move(tape), std::move(layout), std::move(frequencies));
  return [f](double t, const double* y, double* ydot) { f(t, y, nullptr, ydot, nullptr); };
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

Layout LayoutOf(const OriginalSystem& sys) {
  Layout L;
  L.m = static_cast<int>(sys.orders.size());
  L.n = sys.dimension;
  L.K = sys.num_coulomb;
  L.orders = sys.orders;
  return L;
}

void BindSwitched(OriginalSystem* sys) {
  const Layout L = LayoutOf(*sys);
  sys->rhs = MakeRhs(sys->mass_and_rhs, L, sys->frequencies);
  sys->num_switches = sys->mass_and_rhs->num_switches() + L.K;
  if (sys->num_switches == 0) return;
  sys->switched_rhs = MakeSwitchedRhs(sys->mass_and_rhs, L, sys->frequencies);
  sys->next_mode = MakeNextMode(sys->mass_and_rhs, L, sys->frequencies);
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
  else BindSwitched(this);
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

  // Coulomb terms (METHOD.md s.15): each becomes a force symbol, its
  // column, bound, velocity and velocity gradient are outputs of the tape.
  std::vector<ex> equations;
  GiNaC::exset coulomb_terms;
  for (int i = 0; i < m; ++i) {
    try {
      equations.push_back(s.equations[i].subs(params, GiNaC::subs_options::no_pattern));
    } catch (const std::exception& err) {
      throw ModelError(std::string("cannot build the original system: ") + err.what() + " in equation " +
                           std::to_string(i + 1),
                       model.equations[i].where);
    }
  }
  internal::ShareCoulombTerms(&equations);  // coulomb(-v, Fn) is -coulomb(v, Fn): one force
  for (const ex& e : equations)
    e.find(internal::coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2)), coulomb_terms);
  std::vector<GiNaC::symbol> forces;
  std::vector<ex> coulomb_outputs, fn, velocity, gradient;
  GiNaC::exmap to_forces, no_forces;
  for (const ex& term : coulomb_terms) {
    forces.emplace_back("coulomb_force_" + std::to_string(forces.size()));
    to_forces[term] = forces.back();
    no_forces[forces.back()] = 0;
    fn.push_back(term.op(1));
    velocity.push_back(term.op(0));
    for (int i = 1; i <= sys.dimension; ++i) gradient.push_back(term.op(0).diff(GiNaC::ex_to<GiNaC::symbol>(inputs[i])));
    for (const ex& h : highest)
      if (term.op(0).has(h) || term.op(1).has(h) || internal::HasCoulomb(term.op(0)) || internal::HasCoulomb(term.op(1)))
        throw ModelError("coulomb(v, Fn): v and Fn may depend on the states (x, x'), not on the highest derivatives",
                         {model.source, 0, 0});
  }
  sys.num_coulomb = static_cast<int>(forces.size());
  for (ex& e : equations) e = e.subs(to_forces);
  std::vector<ex> mass, rhs;
  GiNaC::exmap zero = no_forces;
  for (const ex& h : highest) zero[h] = 0;
  for (int i = 0; i < m; ++i) {
    const SourceLocation& where = model.equations[i].where;
    ex e;
    try {
      e = equations[i];
      for (const auto& f : forces) {
        const ex c = e.diff(f);
        if (c.has(f) || std::any_of(highest.begin(), highest.end(), [&](const ex& h) { return c.has(h); }))
          throw ModelError("a coulomb() force must enter equation " + std::to_string(i + 1) + " linearly", where);
        coulomb_outputs.push_back(c);
      }
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
  // c_k per equation: coulomb_outputs is [equation][force]; the tape wants [force][equation].
  const int K = sys.num_coulomb;
  for (int k = 0; k < K; ++k)
    for (int i = 0; i < m; ++i) outputs.push_back(coulomb_outputs[i * K + k]);
  outputs.insert(outputs.end(), fn.begin(), fn.end());
  outputs.insert(outputs.end(), velocity.begin(), velocity.end());
  outputs.insert(outputs.end(), gradient.begin(), gradient.end());
  try {
    sys.mass_and_rhs =
        std::make_shared<const CompiledFunction>(internal::Compile(outputs, inputs));
  } catch (const std::exception& err) {
    throw ModelError(std::string("cannot compile the original equations: ") + err.what(),
                     {model.source, 0, 0});
  }
  BindSwitched(&sys);
  return sys;
}

}  // namespace rmhb::model
