#include "rmhb/model/internal/symbolic_tools.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/exact_numbers.h"

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
                     std::vector<int>* k, ex* phase, bool* numeric) {
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
  if (numeric) *numeric = true;
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

bool IsNegativeNumber(const ex& e) {
  return GiNaC::is_a<GiNaC::numeric>(e) && GiNaC::ex_to<GiNaC::numeric>(e).is_real() &&
         GiNaC::ex_to<GiNaC::numeric>(e).is_negative();
}

// e = sign * rest with rest printing without a leading minus.
bool SplitSign(const ex& e, ex* rest) {
  if (IsNegativeNumber(e)) {
    *rest = -e;
    return true;
  }
  if (GiNaC::is_a<GiNaC::mul>(e)) {
    for (std::size_t i = 0; i < e.nops(); ++i)
      if (IsNegativeNumber(e.op(i))) {
        *rest = -e;
        return true;
      }
  }
  *rest = e;
  return false;
}

std::string PrintNumber(const GiNaC::numeric& n) {
  std::ostringstream out;
  if (n.is_rational() || !n.is_real()) {
    out << ex(n);
  } else {
    out.precision(17);
    out << n.to_double();
  }
  return out.str();
}

// Precedence: 0 sum, 1 product/quotient, 2 power, 3 atom.
int Precedence(const ex& e) {
  if (GiNaC::is_a<GiNaC::add>(e)) return 0;
  if (GiNaC::is_a<GiNaC::mul>(e)) return 1;
  if (GiNaC::is_a<GiNaC::numeric>(e)) {
    const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(e);
    if (n.is_negative()) return 0;
    return n.is_integer() ? 3 : 1;
  }
  if (GiNaC::is_a<GiNaC::power>(e)) {
    const ex& x = e.op(1);
    if (x == GiNaC::numeric(1, 2)) return 3;  // sqrt(...)
    if (IsNegativeNumber(x)) return 1;        // 1/...
    return 2;
  }
  return 3;
}

std::string Wrapped(const ex& e, int min_precedence) {
  const std::string s = Print(e);
  return Precedence(e) < min_precedence ? "(" + s + ")" : s;
}

}  // namespace

std::string Print(const ex& e) {
  using GiNaC::is_a;
  if (is_a<GiNaC::numeric>(e)) return PrintNumber(GiNaC::ex_to<GiNaC::numeric>(e));
  if (is_a<GiNaC::symbol>(e)) return GiNaC::ex_to<GiNaC::symbol>(e).get_name();
  if (is_a<GiNaC::constant>(e)) return e == GiNaC::Pi ? "pi" : Str(e);
  if (is_a<GiNaC::add>(e)) {
    std::vector<std::pair<std::string, bool>> terms;  // (positive form, negative)
    std::string constant;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      ex rest;
      const bool negative = SplitSign(e.op(i), &rest);
      std::string text = Wrapped(rest, 1);
      if (is_a<GiNaC::numeric>(e.op(i))) constant = (negative ? " - " : " + ") + text;
      else terms.emplace_back(text, negative);
    }
    std::sort(terms.begin(), terms.end());
    // The constant first: "1 + x^2", "-1 + x*y".
    std::string out = constant.empty() ? "" : constant.substr(constant[1] == '-' ? 1 : 3);
    for (const auto& [text, negative] : terms)
      out += out.empty() ? (negative ? "-" : "") + text : (negative ? " - " : " + ") + text;
    return out;
  }
  if (is_a<GiNaC::mul>(e)) {
    ex rest;
    if (SplitSign(e, &rest)) return "-" + Wrapped(rest, 1);
    std::string coefficient;
    std::vector<std::string> numerator, denominator;
    for (std::size_t i = 0; i < e.nops(); ++i) {
      const ex& f = e.op(i);
      if (is_a<GiNaC::numeric>(f)) {
        const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(f);
        if (n.is_rational() && !n.is_integer()) {
          if (n.numer() != 1) coefficient = PrintNumber(n.numer());
          denominator.push_back(PrintNumber(n.denom()));
        } else {
          coefficient = PrintNumber(n);
        }
      } else if (is_a<GiNaC::power>(f) && IsNegativeNumber(f.op(1))) {
        denominator.push_back(Wrapped(GiNaC::pow(f.op(0), -f.op(1)), 2));
      } else {
        numerator.push_back(Wrapped(f, 1));
      }
    }
    std::sort(numerator.begin(), numerator.end());
    std::sort(denominator.begin(), denominator.end());
    std::string out = coefficient;
    for (const auto& f : numerator) out += (out.empty() ? "" : "*") + f;
    if (out.empty()) out = "1";
    if (!denominator.empty()) {
      std::string d;
      for (const auto& f : denominator) d += (d.empty() ? "" : "*") + f;
      out += "/" + (denominator.size() > 1 ? "(" + d + ")" : d);
    }
    return out;
  }
  if (is_a<GiNaC::power>(e)) {
    const ex& base = e.op(0);
    const ex& exponent = e.op(1);
    if (exponent == GiNaC::numeric(1, 2)) return "sqrt(" + Print(base) + ")";
    if (IsNegativeNumber(exponent)) return "1/" + Wrapped(GiNaC::pow(base, -exponent), 2);
    std::string x = Print(exponent);
    if (!(is_a<GiNaC::numeric>(exponent) && GiNaC::ex_to<GiNaC::numeric>(exponent).is_integer()) &&
        !is_a<GiNaC::symbol>(exponent))
      x = "(" + x + ")";
    return Wrapped(base, 3) + "^" + x;
  }
  if (is_a<GiNaC::function>(e)) {
    std::string out = GiNaC::ex_to<GiNaC::function>(e).get_name() + "(";
    for (std::size_t i = 0; i < e.nops(); ++i) out += (i ? ", " : "") + Print(e.op(i));
    return out + ")";
  }
  return Str(e);
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
