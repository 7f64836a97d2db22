#include "rmhb/model/internal/symbolic_tools.h"

#include <cmath>
#include <stdexcept>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/expression_parser.h"

namespace rmhb::model::internal {

using GiNaC::ex;

GiNaC::exmap Bases::KnownValues() const {
  GiNaC::exmap m;
  for (std::size_t i = 0; i < symbols.size(); ++i)
    if (!unknown[i]) m[symbols[i]] = RationalFromDouble(values[i]);
  return m;
}

GiNaC::exmap Bases::AllValues() const {
  GiNaC::exmap m;
  for (std::size_t i = 0; i < symbols.size(); ++i) m[symbols[i]] = RationalFromDouble(values[i]);
  return m;
}

GiNaC::exmap ParameterSubstitution(const SymbolicModel& symbolic, const ParameterValues& values) {
  GiNaC::exmap m;
  for (const auto& [name, sym] : symbolic.parameters) {
    bool is_base = false;
    for (const auto& b : symbolic.bases) is_base = is_base || b == sym;
    if (is_base) continue;
    m[sym] = RationalFromDouble(values.at(name));
  }
  return m;
}

Bases EvaluateBases(const ModelDefinition& model, const ParameterValues& values) {
  const SymbolicModel& s = *model.symbolic;
  GiNaC::exmap all;
  for (const auto& [name, sym] : s.parameters) all[sym] = RationalFromDouble(values.at(name));
  Bases b;
  for (int i = 0; i < model.num_bases(); ++i) {
    const auto& f = model.frequencies[i];
    double w = 0;
    try {
      w = EvaluateConstant(s.frequency_values[i].subs(all));
    } catch (const std::exception& e) {
      throw ModelError(std::string(e.what()) + " in frequency " + std::to_string(i + 1),
                       f.value.where);
    }
    if (!(w > 0) || !std::isfinite(w))
      throw ModelError("base frequency " + std::to_string(i + 1) + " must be finite and > 0 (got " +
                           std::to_string(w) + ")",
                       f.value.where, f.parameter);
    b.symbols.push_back(s.bases[i]);
    b.values.push_back(w);
    b.unknown.push_back(f.unknown);
  }
  return b;
}

bool AnalyzeHarmonic(const ex& arg, const GiNaC::symbol& t, const Bases& bases,
                     std::vector<int>* k, ex* phase) {
  if (!arg.has(t)) return false;
  const ex rate = arg.diff(t);
  if (rate.has(t)) return false;
  *phase = arg.subs(t == 0);
  if (phase->has(t)) return false;
  const int d = static_cast<int>(bases.symbols.size());
  k->assign(d, 0);
  // Symbolic: rate = sum k_i w_i.
  const ex expanded = rate.expand();
  ex rest = expanded;
  bool symbolic = true;
  for (int i = 0; i < d && symbolic; ++i) {
    const ex c = expanded.coeff(bases.symbols[i], 1);
    if (!GiNaC::is_a<GiNaC::numeric>(c) || !GiNaC::ex_to<GiNaC::numeric>(c).is_integer() ||
        GiNaC::abs(GiNaC::ex_to<GiNaC::numeric>(c)) > 1000) {
      symbolic = false;
      break;
    }
    (*k)[i] = GiNaC::ex_to<GiNaC::numeric>(c).to_int();
    rest -= c * bases.symbols[i];
  }
  if (symbolic && rest.expand().is_zero()) return true;
  // Numerically, against the known base values.
  for (int i = 0; i < d; ++i)
    if (bases.unknown[i] && rate.has(bases.symbols[i])) return false;
  double value;
  try {
    value = EvaluateConstant(rate.subs(bases.KnownValues()));
  } catch (const std::exception&) {
    return false;
  }
  auto close = [&](double a) { return std::abs(a - value) <= 1e-12 * std::max(1.0, std::abs(value)); };
  if (d == 1) {
    if (bases.unknown[0]) return false;
    const double q = value / bases.values[0];
    const double r = std::round(q);
    if (std::abs(r) > 1000 || !close(r * bases.values[0])) return false;
    (*k)[0] = static_cast<int>(r);
    return true;
  }
  if (d == 2 && !bases.unknown[0] && !bases.unknown[1]) {
    for (int n = 0; n <= 40; ++n)  // by increasing |k1| + |k2|
      for (int a = -n; a <= n; ++a)
        for (int sign : {1, -1}) {
          const int b = sign * (n - std::abs(a));
          if (close(a * bases.values[0] + b * bases.values[1])) {
            (*k)[0] = a;
            (*k)[1] = b;
            return true;
          }
          if (b == 0) break;
        }
  }
  return false;
}

namespace {

class AngleMap : public GiNaC::map_function {
 public:
  AngleMap(const GiNaC::symbol& t, const Bases& bases, const std::vector<GiNaC::symbol>& angles)
      : t_(t), bases_(bases), angles_(angles) {}
  ex operator()(const ex& e) override {
    if (!e.has(t_)) return e;
    if (GiNaC::is_a<GiNaC::function>(e) && e.nops() == 1) {
      const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
      if (name == "sin" || name == "cos") {
        std::vector<int> k;
        ex phase;
        if (AnalyzeHarmonic(e.op(0), t_, bases_, &k, &phase)) {
          ex arg = phase;
          for (std::size_t i = 0; i < k.size(); ++i) arg += k[i] * angles_[i];
          return name == "sin" ? GiNaC::sin(arg) : GiNaC::cos(arg);
        }
        if (bases_.symbols.size() > 1)
          throw std::invalid_argument(Str(e) +
                                      " is not a harmonic of the base frequencies (cos(k*w*t))");
      }
    }
    return e.map(*this);
  }

 private:
  const GiNaC::symbol& t_;
  const Bases& bases_;
  const std::vector<GiNaC::symbol>& angles_;
};

}  // namespace

ex ToAngles(const ex& e, const GiNaC::symbol& t, const Bases& bases,
            const std::vector<GiNaC::symbol>& angles) {
  AngleMap map(t, bases, angles);
  ex r = map(e);
  if (r.has(t)) {
    if (bases.symbols.size() != 1)
      throw std::invalid_argument(
          "with several base frequencies, t may only appear in cos/sin(k1*w1*t + k2*w2*t)");
    r = r.subs(t == angles[0] / RationalFromDouble(bases.values[0]));
  }
  return r.subs(bases.AllValues());
}

}  // namespace rmhb::model::internal
