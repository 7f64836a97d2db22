// The Python module `rmhb`: the library from notebooks and scripts, with
// NumPy arrays. A model loads and solves exactly as the CLI's (the same
// library calls: examples::LoadModelOrExample, PrepareSolve and the studies
// of rmhb/pipeline/), so a frequency from Python equals `rmhb solve --json`
// to the last bit. Long calls release the GIL.
//   import rmhb
//   m = rmhb.Model("examples/models/duffing.yaml", F=0.5)
//   s = m.solve(order=20);  s.frequencies, s.eval(t)["x"], s.validate()

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/complex.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "frequency_id/frequency_identification.h"
#include "examples/example_model.h"
#include "rmhb/pipeline/branch.h"
#include "rmhb/model/model_error.h"
#include "rmhb/pipeline/analyze.h"
#include "rmhb/pipeline/report.h"
#include "rmhb/pipeline/settings.h"
#include "rmhb/pipeline/stability.h"
#include "rmhb/pipeline/start.h"
#include "rmhb/version.h"

namespace py = pybind11;

namespace rmhb::python {
namespace {

using Array = py::array_t<double>;

Array ToArray(const std::vector<double>& v) { return Array(static_cast<py::ssize_t>(v.size()), v.data()); }

// A solve's result, with the model it belongs to (for eval, validate, stability).
struct Solution {
  std::shared_ptr<const rmhb::Model> model;
  HarmonicBalanceSummary summary;

  const HarmonicSolution& solution() const {
    if (!summary.solution) throw std::invalid_argument("the solve produced no solution: " + summary.solver.message);
    return *summary.solution;
  }
  std::string status() const {
    return !summary.converged() ? ToString(summary.solver.status) : summary.physical ? "converged" : "non_physical";
  }
};

py::dict Coefficients(const HarmonicSolution& s) {
  py::dict out;
  for (int j = 0; j < s.num_variables(); ++j) {
    if (s.variables()[j].role == VariableRole::kAuxiliary) continue;
    std::vector<double> cos = {s.coefficients()(j, 0)}, sin = {0.0};
    for (int k = 1; k < s.basis().size(); ++k) {
      cos.push_back(s.coefficients()(j, 2 * k - 1));
      sin.push_back(s.coefficients()(j, 2 * k));
    }
    out[py::str(s.variables()[j].name)] = py::make_tuple(ToArray(cos), ToArray(sin));
  }
  return out;
}

py::array_t<int> Harmonics(const HarmonicSolution& s) {
  const int K = s.basis().size(), d = s.basis().num_bases();
  py::array_t<int> out({K, d});
  auto view = out.mutable_unchecked<2>();
  for (int k = 0; k < K; ++k)
    for (int b = 0; b < d; ++b) view(k, b) = s.basis().harmonic(k)[b];
  return out;
}

py::dict Eval(const Solution& self, const Array& t) {
  const HarmonicSolution& s = self.solution();
  const auto times = t.unchecked<1>();
  py::dict out;
  for (int j = 0; j < s.num_variables(); ++j) {
    Array values(times.shape(0));
    auto v = values.mutable_unchecked<1>();
    for (py::ssize_t i = 0; i < times.shape(0); ++i) v(i) = s.Value(j, times(i));
    out[py::str(s.variables()[j].name)] = values;
  }
  return out;
}

py::dict Validate(const Solution& self, int periods) {
  const HarmonicSolution& s = self.solution();
  if (periods < 1) throw std::invalid_argument("periods must be >= 1");
  const double slowest = *std::min_element(s.frequencies().begin(), s.frequencies().end());
  integrators::ValidationReport v;
  {
    py::gil_scoped_release release;
    v = ValidateOriginal(*self.model, s, periods * 2 * M_PI / slowest);
  }
  return py::dict(py::arg("ok") = v.ok, py::arg("max_error") = v.max_error, py::arg("integrator") = v.integrator,
                  py::arg("message") = v.message, py::arg("seconds") = v.seconds);
}

py::list Multipliers(const std::vector<std::complex<double>>& mu) {
  py::list out;
  for (const auto& m : mu) out.append(m);
  return out;
}

py::dict StabilityOf(const Solution& self) {
  StabilitySummary st;
  {
    py::gil_scoped_release release;
    st = Stability(*self.model, self.solution());
  }
  py::dict out(py::arg("verdict") = ToString(st.verdict), py::arg("hill") = ToString(st.hill_verdict),
               py::arg("monodromy") = ToString(st.floquet_verdict));
  if (st.hill) out["hill_multipliers"] = Multipliers(st.hill->multipliers);
  if (st.floquet) out["monodromy_multipliers"] = Multipliers(st.floquet->multipliers);
  if (st.max_multiplier_difference) out["max_multiplier_difference"] = *st.max_multiplier_difference;
  if (!st.hill_note.empty()) out["hill_note"] = st.hill_note;
  if (!st.floquet_note.empty()) out["monodromy_note"] = st.floquet_note;
  if (st.torus()) {  // a torus: exponents, no multipliers
    out["lyapunov"] = ToString(st.lyapunov_verdict);
    out["lyapunov_exponents"] = st.lyapunov->exponents;
    if (st.hill) out["hill_exponents"] = Multipliers(st.hill->exponents);
    if (st.max_exponent_difference) out["max_exponent_difference"] = *st.max_exponent_difference;
    out["largest_exponent"] = st.largest_exponent;
  }
  return out;
}

std::string ToJson(const Solution& self) {
  nlohmann::json out = {{"status", self.status()}, {"order", self.summary.order},
                        {"residual", JsonNumber(self.summary.solver.final_residual)},
                        {"seconds", self.summary.seconds}};
  out.update(PhysicalJson(self.summary));
  if (self.summary.solution) out.update(SolutionJson(*self.summary.solution));
  if (const std::vector<std::string> added = self.model->DefaultConditions(); !added.empty())
    out["default_conditions"] = DefaultConditionsJson(added, self.model->conditions_note);
  return out.dump();
}

// What the keyword arguments of Model.solve set, as the CLI's options would.
SolveSettings Settings(std::optional<int> order, std::optional<int> p, std::optional<double> tol,
                       const std::string& method, const std::string& solver,
                       const std::optional<std::vector<double>>& frequencies) {
  SolveSettings s;
  if (order && p) throw std::invalid_argument("give order or p, not both");
  if (order || p) s.order = order ? *order : *p, s.order_given = true;
  if (tol) s.tol = *tol;
  s.method = method;
  s.solver = solver;
  if (frequencies) {
    for (double w : *frequencies) {
      char text[64];
      std::snprintf(text, sizeof text, "%s%.17g", s.frequencies.empty() ? "" : ",", w);
      s.frequencies += text;
    }
  }
  return s;
}

struct Branch {
  Array parameter, frequency, amplitude, folds;
  py::array_t<double> frequencies;  // points x bases (w1, w2 of a torus)
  py::array_t<bool> stable;
  std::vector<std::string> stability;  // stable, unstable, neutral, unknown
  std::string status, message;
  std::vector<std::string> stability_method;  // hill, monodromy or none, per point
  py::list bifurcations;  // located folds, branch points, period doublings, Neimark-Sacker points
};

struct Identification {
  Array bases;
  py::list lines;
  std::string status, message;
};

class Model {
 public:
  Model(const std::string& name, const py::kwargs& kwargs) {
    std::map<std::string, double> parameters;
    for (const auto& [key, value] : kwargs) parameters[py::cast<std::string>(key)] = py::cast<double>(value);
    model_ = std::make_shared<rmhb::Model>(examples::LoadModelOrExample(name, parameters));
  }

  Solution Solve(std::optional<int> order, std::optional<int> p, std::optional<double> tol, const std::string& method,
                 const std::string& solver, const std::optional<std::vector<double>>& frequencies,
                 const std::string& start, const std::string& linear_solver) const {
    if (start != "auto" && start != "guess") throw std::invalid_argument("start must be auto or guess, got '" + start + "'");
    SolveSettings settings = Settings(order, p, tol, method, solver, frequencies);
    settings.linear_solver = linear_solver;  // as --linear-solver; PrepareSolve refuses an unknown name
    settings.default_tol = SolveSettings::kDefaultTolerance;  // as rmhb solve: unless order or p is given
    if (settings.method != "rhb" && settings.method != "hdhb" && settings.method != "aft")
      throw std::invalid_argument("method must be rhb, hdhb or aft, got '" + method + "'");
    py::gil_scoped_release release;
    // As `rmhb solve --start` (SolveModel's start): the guess, then a simulated or identified start.
    auto solve = [&](const rmhb::Model& source) {
      PreparedSolve prepared = PrepareSolve(source, settings);
      ImposeGuessSymmetries(prepared.guess, &prepared.model);  // as SolveModel: the same unknowns, the same answer
      auto model = std::make_shared<const rmhb::Model>(std::move(prepared.model));
      return Solution{model, start == "guess" ? SolveHarmonicBalance(model->problem, prepared.guess, prepared.options)
                                              : SolveFromAnyStart(*model, prepared.guess, prepared.options).summary};
    };
    Solution out = solve(*model_);
    if (start == "guess" || out.summary.usable() || !model_->original_equations) return out;
    // As SolveModel: the recast reached no physical solution, the equations as written may.
    Solution original = solve(OriginalEquationsOf(*model_));
    return original.summary.usable() ? original : out;
  }

  AnalyzeSummary Analyze(std::optional<int> order, double t_end, double transient, int validate_periods) const {
    SolveSettings settings = Settings(order, {}, {}, "rhb", "auto", {});
    settings.default_tol = SolveSettings::kDefaultTolerance;  // as rmhb analyze
    py::gil_scoped_release release;
    const PreparedSolve prepared = PrepareSolve(*model_, settings);
    AnalyzeOptions options;
    options.solve = prepared.options;
    options.t_end = t_end;
    options.transient = transient;
    options.validate_periods = validate_periods;
    return rmhb::Analyze(prepared.model, options);
  }

  Branch Continuation(const std::string& parameter, double start, double stop, std::optional<int> order,
                        bool natural, int steps) const {
    if (start == stop) throw std::invalid_argument("continuation: start == stop");
    if (steps < 1) throw std::invalid_argument("steps must be >= 1");
    BranchSummary branch;
    {
      py::gil_scoped_release release;
      SolveSettings settings = Settings(order, {}, {}, "rhb", "auto", {});
      settings.default_torus_tol = SolveSettings::kDefaultTolerance;  // as rmhb solve --continue
      const PreparedSolve prepared = PrepareSolve(WithParameters(*model_, {{parameter, start}}), settings);
      ContinueOptions options;
      options.parameter = parameter;
      options.from = start;
      options.to = stop;
      options.harmonic_balance = prepared.options;
      options.natural = natural;
      options.steps = steps;
      branch = ContinueModel(prepared.model, prepared.guess, options);
    }
    const ContinuationSummary& summary = branch.continuation;
    std::vector<double> lambda, frequency, amplitude, folds;
    std::vector<std::string> stability;
    py::array_t<bool> stable(static_cast<py::ssize_t>(summary.points.size()));
    auto flags = stable.mutable_unchecked<1>();
    py::array_t<double> frequencies({static_cast<py::ssize_t>(summary.points.size()),
                                     static_cast<py::ssize_t>(branch.bases)});
    auto w = frequencies.mutable_unchecked<2>();
    for (size_t i = 0; i < summary.points.size(); ++i) {
      const ContinuationPoint& p = summary.points[i];
      lambda.push_back(p.parameter);
      frequency.push_back(p.solution.frequencies()[0]);
      for (int b = 0; b < branch.bases; ++b)
        w(static_cast<py::ssize_t>(i), b) = p.solution.frequencies()[static_cast<size_t>(b)];
      amplitude.push_back(branch.reports[i].peak);
      stability.push_back(branch.reports[i].stability);  // a torus': its Lyapunov verdict
      flags(static_cast<py::ssize_t>(i)) = branch.reports[i].stability == "stable";
      if (p.fold) folds.push_back(p.parameter);
    }
    std::vector<std::string> methods;
    for (const ContinuationPoint& p : summary.points) methods.push_back(ToString(p.stability_method));
    py::list bifurcations;
    for (const BifurcationPoint& b : summary.bifurcations) {
      py::dict d;
      d["type"] = ToString(b.type);
      d["parameter"] = b.parameter;
      d["multiplier"] = b.multiplier;
      d["located"] = b.located;
      d["method"] = b.method;
      if (b.type == BifurcationType::kNeimarkSacker) d["torus_frequency"] = b.torus_frequency;
      bifurcations.append(d);
    }
    return Branch{ToArray(lambda), ToArray(frequency), ToArray(amplitude), ToArray(folds), frequencies, stable, stability,
                  ToString(summary.status), summary.message, methods, bifurcations};
  }

  py::dict Simulate(double t_end, double dt) const {
    if (!(t_end > 0) || !(dt > 0) || !std::isfinite(t_end) || t_end / dt > 2e7)
      throw std::invalid_argument("simulate: need finite t_end > 0, dt > 0 and at most 2e7 samples");
    std::vector<double> times;
    for (long i = 0; i * dt <= t_end * (1 + 1e-12); ++i) times.push_back(static_cast<double>(i) * dt);
    integrators::IntegratorOptions options;
    options.method = model_->stiff ? integrators::IntegratorOptions::Method::kBdf
                                   : integrators::IntegratorOptions::Method::kAdams;
    integrators::IntegrationResult r;
    {
      py::gil_scoped_release release;
      r = SimulateOriginal(*model_, model_->problem.frequencies, model_->initial_state, times, options);
    }
    if (!r.ok()) throw std::runtime_error("simulate: the integration stopped: " + r.message);
    py::dict out;
    out["t"] = ToArray(r.trajectory.times);
    for (int c = 0; c < r.trajectory.dimension(); ++c) {
      const Eigen::VectorXd column = r.trajectory.states.col(c);
      out[py::str(model_->state_names[c])] = ToArray(std::vector<double>(column.data(), column.data() + column.size()));
    }
    return out;
  }

  const std::string& name() const { return model_->name; }
  const std::string& equation() const { return model_->equation; }
  int default_order() const { return model_->default_order; }

 private:
  std::shared_ptr<const rmhb::Model> model_;
};

Identification Identify(const Array& t, const py::array_t<double, py::array::c_style | py::array::forcecast>& signal) {
  const auto time = t.unchecked<1>();
  if (time.shape(0) < 16) throw std::invalid_argument("identify: at least 16 samples");
  if (signal.ndim() != 1 && signal.ndim() != 2) throw std::invalid_argument("identify: signal must be 1-D or 2-D");
  const py::ssize_t n = signal.shape(0), channels = signal.ndim() == 1 ? 1 : signal.shape(1);
  if (n != time.shape(0)) throw std::invalid_argument("identify: t and signal differ in length");
  frequency_id::Signal s;
  s.t0 = time(0);
  s.dt = (time(n - 1) - time(0)) / static_cast<double>(n - 1);
  for (py::ssize_t i = 1; i < n; ++i)
    if (std::abs(time(i) - time(i - 1) - s.dt) > 1e-9 * std::max(1.0, std::abs(s.dt)))
      throw std::invalid_argument("identify: t must be uniformly spaced");
  s.samples.resize(n, channels);
  const double* data = signal.data();
  for (py::ssize_t i = 0; i < n; ++i)
    for (py::ssize_t c = 0; c < channels; ++c) s.samples(i, c) = data[i * channels + c];
  frequency_id::IdentificationSummary summary;
  {
    py::gil_scoped_release release;
    frequency_id::IdentifyFrequencies(frequency_id::IdentificationOptions{}, s, &summary);
  }
  std::vector<double> bases;
  for (const auto& b : summary.bases) bases.push_back(b.frequency);
  py::list lines;
  for (const auto& c : summary.components)
    lines.append(py::dict(py::arg("frequency") = c.frequency, py::arg("label") = c.label,
                          py::arg("amplitude") = std::vector<double>(c.amplitude.data(), c.amplitude.data() + c.amplitude.size()),
                          py::arg("phase") = std::vector<double>(c.phase.data(), c.phase.data() + c.phase.size())));
  return Identification{ToArray(bases), lines, frequency_id::ToString(summary.status), summary.message};
}

}  // namespace
}  // namespace rmhb::python

PYBIND11_MODULE(rmhb, m) {
  using namespace rmhb::python;
  namespace r = rmhb;
  m.doc() = "rmhb: periodic and quasi-periodic steady states by reconstruction harmonic balance";
  m.attr("__version__") = RMHB_VERSION_STRING;
  py::register_exception<r::model::ModelError>(m, "ModelError", PyExc_ValueError);

  py::class_<Solution>(m, "Solution")
      .def_property_readonly("status", &Solution::status)
      .def_property_readonly("converged", [](const Solution& s) { return s.summary.usable(); })
      .def_property_readonly("frequencies", [](const Solution& s) { return ToArray(s.solution().frequencies()); })
      .def_property_readonly("order", [](const Solution& s) { return s.summary.order; })
      .def_property_readonly("residual", [](const Solution& s) { return s.summary.solver.final_residual; })
      .def_property_readonly("seconds", [](const Solution& s) { return s.summary.seconds; })
      .def_property_readonly("harmonics", [](const Solution& s) { return Harmonics(s.solution()); })
      .def_property_readonly("coefficients", [](const Solution& s) { return Coefficients(s.solution()); })
      .def("eval", &Eval, py::arg("t"), "Every variable at the times t: dict name -> ndarray")
      .def("validate", &Validate, py::arg("periods") = 1,
           "Max error against an integration of the original equations (CVODE or IDA)")
      .def("stability", &StabilityOf, "Hill's method and the monodromy matrix: verdict and multipliers")
      .def("to_json", &ToJson)
      .def("__repr__", [](const Solution& s) { return "<rmhb.Solution " + s.status() + ">"; });

  py::class_<r::AnalyzeSummary>(m, "Analysis")
      .def_property_readonly("status", [](const r::AnalyzeSummary& a) { return std::string(r::ToString(a.status)); })
      .def_property_readonly("ok", &r::AnalyzeSummary::ok)
      .def_property_readonly("message", [](const r::AnalyzeSummary& a) { return a.message; })
      .def_property_readonly("frequencies", [](const r::AnalyzeSummary& a) {
        return a.solve && a.solve->solution ? ToArray(a.solve->solution->frequencies()) : ToArray({});
      })
      .def_property_readonly("validation_error", [](const r::AnalyzeSummary& a) {
        return a.validation ? a.validation->max_error : std::nan("");
      })
      .def_property_readonly("seconds", [](const r::AnalyzeSummary& a) { return a.seconds; })
      .def("report", &r::AnalyzeSummary::FullReport);

  py::class_<Branch>(m, "Branch")
      .def_readonly("parameter", &Branch::parameter)
      .def_readonly("frequency", &Branch::frequency)
      .def_readonly("frequencies", &Branch::frequencies)
      .def_readonly("amplitude", &Branch::amplitude)
      .def_readonly("stable", &Branch::stable)
      .def_readonly("stability", &Branch::stability)
      .def_readonly("folds", &Branch::folds)
      .def_readonly("status", &Branch::status)
      .def_readonly("message", &Branch::message)
      .def_readonly("stability_method", &Branch::stability_method)
      .def_readonly("bifurcations", &Branch::bifurcations);

  py::class_<Identification>(m, "Identification")
      .def_readonly("bases", &Identification::bases)
      .def_readonly("lines", &Identification::lines)
      .def_readonly("status", &Identification::status)
      .def_readonly("message", &Identification::message);

  py::class_<Model>(m, "Model")
      .def(py::init<std::string, py::kwargs>(), py::arg("path_or_example_name"),
           "A model file or a bundled example; keyword arguments override its parameters")
      .def("solve", &Model::Solve, py::arg("order") = py::none(), py::arg("p") = py::none(),
           py::arg("tol") = py::none(), py::arg("method") = "rhb", py::arg("solver") = "auto",
           py::arg("frequencies") = py::none(), py::arg("start") = "auto", py::arg("linear_solver") = "auto")
      .def("analyze", &Model::Analyze, py::arg("order") = py::none(), py::arg("t_end") = 0.0,
           py::arg("transient") = -1.0, py::arg("validate_periods") = 20,
           "Integrate, identify the frequencies, seed, solve and validate")
      .def("continuation", &Model::Continuation, py::arg("parameter"), py::arg("start"), py::arg("stop"),
           py::arg("order") = py::none(), py::arg("natural") = false, py::arg("steps") = 20,
           "The branch as `parameter` goes from start to stop: NumPy columns parameter, frequency, "
           "amplitude, stable, and the folds' parameter values")
      .def("simulate", &Model::Simulate, py::arg("t_end"), py::arg("dt"),
           "The original equations integrated from the model's initial state: dict t and every state")
      .def_property_readonly("name", &Model::name)
      .def_property_readonly("equation", &Model::equation)
      .def_property_readonly("default_order", &Model::default_order);

  m.def("identify", &Identify, py::arg("t"), py::arg("signal"),
        "Base frequencies and labelled lines of a uniformly sampled signal (one channel per column)");
}
