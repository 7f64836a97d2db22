#include "rmhb/model/recast.h"

#include <cmath>
#include <algorithm>
#include <map>
#include <memory>
#include <set>
#include <sstream>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/exact_numbers.h"
#include "rmhb/model/internal/nonsmooth.h"
#include "rmhb/model/internal/symbolic_model.h"
#include "rmhb/model/internal/symbolic_tools.h"

namespace rmhb::model {
namespace {

using GiNaC::ex;
using GiNaC::is_a;
using internal::SymbolicModel;

constexpr int kMaxAuxiliaries = 400;
constexpr std::size_t kMaxTerms = 20000;
// p^(a/b) becomes a root beta^b = p for b up to this (degree b); beyond, the
// derivative rule for powers keeps the degree low.
constexpr int kMaxRootIndex = 4;

using ExSet = std::set<ex, GiNaC::ex_is_less>;
template <class V>
using ExMap = std::map<ex, V, GiNaC::ex_is_less>;

// (rule, recast argument): the memo key of an auxiliary.
using RuleKey = std::pair<std::string, ex>;
struct RuleKeyLess {
  bool operator()(const RuleKey& a, const RuleKey& b) const {
    if (a.first != b.first) return a.first < b.first;
    return GiNaC::ex_is_less()(a.second, b.second);
  }
};

// Where a symbol of the recast lives in the polynomial system.
struct SlotRef {
  int variable = -1;
  int derivative = 0;
};

class Recaster {
 public:
  Recaster(const ModelDefinition& model, const ParameterValues& overrides, bool problem_only)
      : model_(model), s_(*model.symbolic), problem_only_(problem_only) {
    values_ = model.ParameterValuesWith(overrides);
    bases_ = internal::EvaluateBases(model, values_);
    params_ = internal::ParameterSubstitution(s_, values_);
    const int n = static_cast<int>(model.variables.size());
    chain_.resize(n);
    for (int v = 0; v < n; ++v) {
      chain_[v] = std::max(model.orders[v], 1);
      for (const auto& sym : s_.derivatives[v]) {
        dynamic_.insert(sym);
        user_sym_[sym] = {v, static_cast<int>(&sym - s_.derivatives[v].data())};
      }
    }
    for (std::size_t i = 0; i < bases_.symbols.size(); ++i)
      if (bases_.unknown[i]) unknown_bases_.insert(bases_.symbols[i]);
    for (const auto& v : model.variables) taken_.insert(v);
    base_value_used_.assign(bases_.symbols.size(), false);
  }

  RecastResult Run() {
    RecastResult result;
    result.model_name = model_.name;
    result.source = model_.source;
    result.parameters = values_;

    // 1. Recast every equation (creates auxiliaries and their equations).
    // A piecewise-smooth equation (max, abs, ..., coulomb) is no polynomial:
    // it stays as written and is evaluated pointwise (METHOD.md s.15).
    std::vector<ex> user;
    std::vector<bool> nonsmooth;
    for (std::size_t i = 0; i < s_.equations.size(); ++i) {
      source_ = static_cast<int>(i);
      Guarded([&] {
        ex e = Substituted(s_.equations[i]);
        nonsmooth.push_back(internal::HasNonSmooth(e));
        user.push_back(nonsmooth.back() ? e : R(e));
      });
    }
    source_ = -1;
    internal::ShareCoulombTerms(&user);  // one friction force between two bodies

    // 2. Lay out the variables: user chains, then auxiliaries.
    PolynomialSystem& system = result.problem.system;
    std::vector<std::vector<int>> chain_index(chain_.size());
    for (std::size_t v = 0; v < chain_.size(); ++v) {
      const std::string& name = model_.variables[v];
      for (int j = 0; j < chain_[v]; ++j) {
        std::string var = j == 0 ? name : UniqueName(name + "_d" + std::to_string(j));
        chain_index[v].push_back(system.AddVariable(
            var, VariableRole::kState, j == 0 ? "" : name + std::string(j, '\'')));
      }
    }
    for (auto& a : aux_) {
      a.index = system.AddVariable(a.name, VariableRole::kAuxiliary, internal::Print(a.definition));
      result.definitions.push_back(a.name + " = " + internal::Print(a.definition));
    }
    for (std::size_t v = 0; v < chain_.size(); ++v) {
      const int L = chain_[v];
      for (int j = 0; j <= L; ++j) {
        const ex& sym = s_.derivatives[v][j];
        slots_[sym] = j < L ? SlotRef{chain_index[v][j], 0} : SlotRef{chain_index[v][L - 1], 1};
      }
    }
    for (const auto& a : aux_) {
      slots_[a.sym] = {a.index, 0};
      slots_[a.dsym] = {a.index, 1};
    }

    // 3. Equations: chains, the user's, the auxiliaries'.
    for (std::size_t v = 0; v < chain_.size(); ++v)
      for (int j = 0; j + 1 < chain_[v]; ++j)
        system.AddEquation(Polynomial::Derivative(chain_index[v][j]) -
                           Polynomial::Variable(chain_index[v][j + 1]));
    for (std::size_t i = 0; i < user.size(); ++i) {
      source_ = static_cast<int>(i);
      if (nonsmooth[i]) {
        PointwiseEquation pointwise;
        const std::string error = MakePointwise(static_cast<int>(i), user[i], user, &pointwise);
        if (!error.empty()) Fail(error);
        system.AddPointwiseEquation(std::move(pointwise));
        continue;
      }
      Guarded([&] { system.AddEquation(P(user[i])); });
    }
    in_auxiliary_ = true;
    for (const auto& eq : equations_) {
      source_ = eq.source;
      Guarded([&] { system.AddEquation(P(eq.lhs), eq.balance_constant); });
    }
    in_auxiliary_ = false;
    source_ = -1;
    for (int i = 0; i < static_cast<int>(user.size()); ++i) {
      const int row = static_cast<int>(system.num_equations() - equations_.size() - user.size()) + i;
      if (!nonsmooth[i] && system.equations()[row].lhs.IsZero()) {
        source_ = i;
        Fail("the equation vanishes with these parameter values");
      }
    }
    try {
      system.Validate();
    } catch (const std::invalid_argument& e) {
      Fail(std::string("the recast system is not valid with these parameter values: ") + e.what());
    }
    result.degree = system.Degree();

    // 4. Frequencies and conditions.
    result.problem.frequencies = bases_.values;
    result.problem.unknown_frequency = bases_.unknown;
    for (std::size_t i = 0; i < s_.conditions.size(); ++i) {
      condition_ = static_cast<int>(i);
      Guarded([&] {
        ex c = Substituted(s_.conditions[i]);
        result.problem.conditions.push_back(MakeCondition(c, model_.conditions[i].text));
      });
    }
    condition_ = -1;
    result.num_user_conditions = static_cast<int>(result.problem.conditions.size());
    for (const auto& a : aux_) {
      if (!a.pinned) continue;
      source_ = a.source;
      ex def;
      try {
        def = a.definition.subs(s_.t == 0);
      } catch (const std::exception& err) {
        Fail("the auxiliary " + a.name + " = " + internal::Print(a.definition) +
             " is undefined at t = 0, where it must be pinned (" + err.what() + ")");
      }
      Guarded([&] {
        result.problem.conditions.push_back(
            MakeCondition(a.sym - def, "pin " + a.name + "(0) = " + internal::Print(def)));
        result.problem.conditions.back().pinned_variable = a.index;
      });
    }
    source_ = -1;
    if (!problem_only_) BuildOriginalProblem(&result);

    // 5. Guess.
    BuildGuess(system, &result);
    for (const auto& a : aux_) NoteBaseValues(a.definition, true);  // problem.definitions
    result.frequency_parameters = FrequencyParameters();
    if (problem_only_) return result;

    // 6. The original system for the integrators.
    try {
      OriginalSystem original = BuildOriginalSystem(model_, values_, bases_.values);
      for (std::size_t v = 0; v < chain_.size(); ++v)
        for (int j = 0; j < std::max(model_.orders[v], 1); ++j)
          original.sources.push_back({chain_index[v][j], 0});
      result.original = std::move(original);
    } catch (const ModelError& e) {
      result.original_error = e.what();
    }
    if (result.original) result.initial_state = InitialState(*result.original);
    return result;
  }

 private:
  struct Aux {
    std::string name;
    GiNaC::symbol sym;
    GiNaC::symbol dsym;
    ex definition;  // of recast symbols (user derivatives, earlier auxiliaries, t, bases)
    bool pinned = false;
    int source = -1;
    int index = -1;
  };
  struct PendingEquation {
    ex lhs;
    bool balance_constant = true;
    int source = -1;
  };

  // ---- errors -----------------------------------------------------------------
  [[noreturn]] void Fail(const std::string& message, const std::string& symbol = "") const {
    if (condition_ >= 0)
      throw ModelError(message + " in condition " + std::to_string(condition_ + 1),
                       model_.conditions[condition_].where, symbol);
    if (source_ >= 0)
      throw ModelError(message + " in equation " + std::to_string(source_ + 1),
                       model_.equations[source_].where, symbol);
    throw ModelError(message, {model_.source, 0, 0}, symbol);
  }

  // Runs f, turning exceptions from GiNaC (pole errors, overflow) into a
  // ModelError located at the current equation or condition.
  template <class F>
  void Guarded(F f) {
    try {
      f();
    } catch (const ModelError&) {
      throw;
    } catch (const std::exception& err) {
      Fail(err.what());
    }
  }

  ex Substituted(const ex& e) const {
    try {
      return e.subs(params_, GiNaC::subs_options::no_pattern);
    } catch (const std::exception& err) {
      Fail(std::string("cannot substitute the parameter values (") + err.what() + ")");
    }
  }

  std::string UniqueName(const std::string& base) {
    std::string name = base;
    for (int i = 2; taken_.count(name); ++i) name = base + "_" + std::to_string(i);
    taken_.insert(name);
    return name;
  }

  // ---- symbol classes ------------------------------------------------------------
  bool IsDynamic(const ex& e) const { return dynamic_.count(e) > 0; }
  bool FreeOfDynamic(const ex& e) const {
    if (is_a<GiNaC::symbol>(e)) return !IsDynamic(e);
    for (std::size_t i = 0; i < e.nops(); ++i)
      if (!FreeOfDynamic(e.op(i))) return false;
    return true;
  }
  bool IsConstant(const ex& e) const { return FreeOfDynamic(e) && !e.has(s_.t); }
  // Degree in the dynamic symbols (time functions count 0).
  int Degree(const ex& e) const {
    if (is_a<GiNaC::symbol>(e)) return IsDynamic(e) ? 1 : 0;
    if (is_a<GiNaC::add>(e)) {
      int d = 0;
      for (std::size_t i = 0; i < e.nops(); ++i) d = std::max(d, Degree(e.op(i)));
      return d;
    }
    if (is_a<GiNaC::mul>(e)) {
      int d = 0;
      for (std::size_t i = 0; i < e.nops(); ++i) d += Degree(e.op(i));
      return d;
    }
    if (is_a<GiNaC::power>(e) && is_a<GiNaC::numeric>(e.op(1)) &&
        GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_pos_integer())
      return Degree(e.op(0)) * GiNaC::ex_to<GiNaC::numeric>(e.op(1)).to_int();
    return 0;
  }

  // ---- auxiliaries -----------------------------------------------------------------
  static std::string Slug(const ex& g) {
    if (!is_a<GiNaC::symbol>(g)) return "";
    std::string name = GiNaC::ex_to<GiNaC::symbol>(g).get_name();
    int primes = 0;
    while (!name.empty() && name.back() == '\'') {
      name.pop_back();
      ++primes;
    }
    if (primes) name += "_d" + std::to_string(primes);
    return name;
  }

  Aux& NewAux(const std::string& kind, const ex& argument, const ex& definition, bool pinned) {
    if (static_cast<int>(aux_.size()) >= kMaxAuxiliaries)
      Fail("the recast needs more than " + std::to_string(kMaxAuxiliaries) + " auxiliary variables");
    const std::string slug = Slug(argument);
    std::string name = slug.empty() ? kind + "_" + std::to_string(++counter_[kind]) : kind + "_" + slug;
    name = UniqueName(name);
    Aux a;
    a.name = name;
    a.sym = GiNaC::symbol(name);
    a.dsym = GiNaC::symbol(name + "'");
    a.definition = definition;
    a.pinned = pinned;
    a.source = source_;
    dynamic_.insert(a.sym);
    dynamic_.insert(a.dsym);
    aux_.push_back(a);
    return aux_.back();
  }

  void AddEquation(const ex& lhs, bool balance_constant) {
    equations_.push_back({lhs, balance_constant, source_});
  }

  // Total time derivative of a recast expression.
  ex TimeDerivative(const ex& g) {
    ex d = 0;
    for (std::size_t v = 0; v < chain_.size(); ++v) {
      const auto& syms = s_.derivatives[v];
      for (std::size_t j = 0; j + 1 < syms.size(); ++j) {
        if (!g.has(syms[j])) continue;
        d += g.diff(syms[j]) * syms[j + 1];
        // x^(j+1) must be a derivative slot or a state: extend the chain.
        chain_[v] = std::max(chain_[v], static_cast<int>(j) + 1);
      }
      if (g.has(syms.back())) Fail("derivative order too high for the recast");
    }
    for (const auto& a : aux_)
      if (g.has(a.sym)) d += g.diff(a.sym) * a.dsym;
    if (g.has(s_.t)) d += g.diff(s_.t);
    return d;
  }

  ex Reciprocal(const ex& p) {
    if (IsConstant(p)) {
      if (p.is_zero()) Fail("division by zero");
      return 1 / p;
    }
    const RuleKey key{"inv", p};
    if (auto it = memo_.find(key); it != memo_.end()) return it->second;
    ex q = p;
    if (Degree(p) >= 2) {
      // Name the denominator first: keeps r q - 1 at degree 2 (appendix form).
      Aux& den = NewAux("den", ex(0), p, false);
      const ex sym = den.sym;
      AddEquation(sym - p, true);
      q = sym;
    }
    Aux& r = NewAux("inv", q, 1 / q, false);
    const ex sym = r.sym;
    AddEquation(sym * q - 1, true);
    memo_[key] = sym;
    return sym;
  }

  ex Root(const ex& p, int index) {
    if (IsConstant(p)) return GiNaC::pow(p, GiNaC::numeric(1, index));
    const RuleKey key{"root" + std::to_string(index), p};
    if (auto it = memo_.find(key); it != memo_.end()) return it->second;
    const std::string kind = index == 2 ? "sqrt" : index == 3 ? "cbrt" : "root" + std::to_string(index);
    Aux& b = NewAux(kind, p, GiNaC::pow(p, GiNaC::numeric(1, index)), false);
    const ex sym = b.sym;
    AddEquation(GiNaC::pow(sym, index) - p, true);
    memo_[key] = sym;
    return sym;
  }

  // An auxiliary defined through its derivative: u' = rate(u), pinned at t = 0.
  ex Differential(const std::string& kind, const ex& g, const ex& definition,
                  const std::function<ex(const ex& u, const ex& dg)>& equation,
                  const std::string& name = "") {
    const RuleKey key{kind, g};
    if (auto it = memo_.find(key); it != memo_.end()) return it->second;
    const ex dg = TimeDerivative(g);
    Aux& u = NewAux(name.empty() ? kind : name, g, definition, true);
    const ex sym = u.sym, dsym = u.dsym;
    AddEquation(dsym - equation(sym, dg), false);
    memo_[key] = sym;
    return sym;
  }

  // A pair defined through each other's derivative (sin & cos, sinh & cosh).
  std::pair<ex, ex> Pair(const std::string& first, const std::string& second, const ex& g,
                         const ex& first_definition, const ex& second_definition, double sign) {
    const RuleKey key{first + second, g};
    if (auto it = memo_.find(key); it != memo_.end())
      return {it->second.op(0), it->second.op(1)};
    const ex dg = TimeDerivative(g);
    Aux& a = NewAux(first, g, first_definition, true);
    const ex s = a.sym, ds = a.dsym;
    Aux& b = NewAux(second, g, second_definition, true);
    const ex c = b.sym, dc = b.dsym;
    AddEquation(ds - dg * c, false);         // s' = g' c
    AddEquation(dc - sign * dg * s, false);  // c' = -g' s (sin/cos), +g' s (sinh/cosh)
    memo_[key] = GiNaC::lst{s, c};
    return {s, c};
  }

  // ---- the recast proper ---------------------------------------------------------
  ex R(const ex& e) {
    if (IsConstant(e)) return e;
    if (auto it = cache_.find(e); it != cache_.end()) return it->second;
    ex r;
    if (is_a<GiNaC::symbol>(e)) {
      r = e;
    } else if (is_a<GiNaC::add>(e)) {
      r = 0;
      for (const ex& op : SortedOperands(e)) r += R(op);
    } else if (is_a<GiNaC::mul>(e)) {
      r = 1;
      for (const ex& op : SortedOperands(e)) r *= R(op);
    } else if (is_a<GiNaC::power>(e)) {
      r = RPower(e.op(0), e.op(1));
    } else if (is_a<GiNaC::function>(e)) {
      r = RFunction(e);
    } else {
      Fail("cannot recast " + internal::Print(e));
    }
    cache_[e] = r;
    return r;
  }

  // Operands in the order of their printed form: GiNaC's own order follows
  // hash values of symbols, which differ from run to run, and would make the
  // numbering of the auxiliaries irreproducible.
  static std::vector<ex> SortedOperands(const ex& e) {
    std::vector<std::pair<std::string, ex>> keyed;
    for (std::size_t i = 0; i < e.nops(); ++i) keyed.emplace_back(internal::Print(e.op(i)), e.op(i));
    std::stable_sort(keyed.begin(), keyed.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<ex> out;
    for (auto& k : keyed) out.push_back(k.second);
    return out;
  }

  ex RPower(const ex& base, const ex& exponent) {
    if (!IsConstant(exponent)) return R(GiNaC::exp(exponent * GiNaC::log(base)));
    if (!is_a<GiNaC::numeric>(exponent)) {  // x^pi
      const ex g = R(base);
      const ex r = Reciprocal(g);
      return Differential("pow" + internal::Print(exponent), g, GiNaC::pow(g, exponent),
                          [r, exponent](const ex& u, const ex& dg) { return exponent * dg * u * r; },
                          "pow");
    }
    const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(exponent);
    if (n.is_integer()) {
      const int k = n.to_int();
      if (k >= 0) return GiNaC::pow(R(base), k);
      return GiNaC::pow(Reciprocal(R(base)), -k);
    }
    if (n.is_rational() && n.denom() <= kMaxRootIndex && GiNaC::abs(n.numer()) <= 64) {
      const int q = n.denom().to_int();
      const int p = n.numer().to_int();
      const ex beta = Root(R(base), q);
      return p > 0 ? GiNaC::pow(beta, p) : GiNaC::pow(Reciprocal(beta), -p);
    }
    // Any other real exponent: u = g^n through u' = n g' u / g (degree
    // deg(g') + 2 instead of beta^q - g = 0 of degree q).
    const ex g = R(base);
    const ex r = Reciprocal(g);
    return Differential("pow" + internal::Print(exponent), g, GiNaC::pow(g, exponent),
                        [r, exponent](const ex& u, const ex& dg) { return exponent * dg * u * r; },
                        "pow");
  }

  ex RFunction(const ex& f) {
    const std::string name = GiNaC::ex_to<GiNaC::function>(f).get_name();
    if (f.nops() != 1) Fail("unsupported function " + internal::Print(f), name);
    const ex& arg = f.op(0);
    if ((name == "sin" || name == "cos") && FreeOfDynamic(arg)) {
      std::vector<int> k;
      ex phase;
      if (Harmonic(arg, &k, &phase)) return f;  // forcing
      if (!arg.diff(s_.t).has(s_.t))  // linear in t, but not a harmonic
        Fail(internal::Print(f) + " is not a harmonic of the base frequencies: time may only "
             "appear as cos(k*w*t + phase), sin(k*w*t + phase) with integer k");
      // Otherwise (cos(cos(w t)), ...): an auxiliary like any other.
    }
    const ex g = R(arg);
    if (name == "exp")
      return Differential("exp", g, GiNaC::exp(g), [](const ex& u, const ex& dg) { return dg * u; });
    if (name == "log") {
      const ex r = Reciprocal(g);
      return Differential("log", g, GiNaC::log(g), [r](const ex&, const ex& dg) { return dg * r; });
    }
    if (name == "sin" || name == "cos") {
      auto [s, c] = Pair("sin", "cos", g, GiNaC::sin(g), GiNaC::cos(g), -1.0);
      return name == "sin" ? s : c;
    }
    if (name == "sinh" || name == "cosh") {
      auto [s, c] = Pair("sinh", "cosh", g, GiNaC::sinh(g), GiNaC::cosh(g), 1.0);
      return name == "sinh" ? s : c;
    }
    if (name == "tan")
      return Differential("tan", g, GiNaC::tan(g),
                          [](const ex& u, const ex& dg) { return dg * (1 + u * u); });
    if (name == "tanh")
      return Differential("tanh", g, GiNaC::tanh(g),
                          [](const ex& u, const ex& dg) { return dg * (1 - u * u); });
    if (name == "asin" || name == "acos") {
      const ex w = Reciprocal(Root(1 - g * g, 2));
      const double sign = name == "asin" ? 1.0 : -1.0;
      return Differential(name, g, name == "asin" ? GiNaC::asin(g) : GiNaC::acos(g),
                          [w, sign](const ex&, const ex& dg) { return sign * dg * w; });
    }
    if (name == "atan") {
      const ex w = Reciprocal(1 + g * g);
      return Differential("atan", g, GiNaC::atan(g), [w](const ex&, const ex& dg) { return dg * w; });
    }
    Fail("the function '" + name + "' cannot be recast", name);
  }

  // ---- what `problem` uses of the base values ---------------------------------------
  // A base symbol is never substituted by its value until an expression
  // becomes a number (a coefficient, a condition, a pointwise equation, a
  // definition), so noting it there says exactly which base values `problem`
  // depends on beyond problem.frequencies. `time`: explicit t counts as every
  // base (it becomes theta/w, or a forcing recognised at the known rates).
  void NoteBaseValues(const ex& e, bool time) const {
    if (!tracking_) return;
    const bool all = time && e.has(s_.t);
    for (std::size_t i = 0; i < bases_.symbols.size(); ++i)
      if (all || e.has(bases_.symbols[i])) base_value_used_[i] = true;
  }

  // AnalyzeHarmonic, noting that the answer depends on every base value when
  // it was decided numerically (cos(2*t) is the first harmonic at w = 2 only).
  bool Harmonic(const ex& arg, std::vector<int>* k, ex* phase) const {
    bool numeric = false;
    const bool harmonic = internal::AnalyzeHarmonic(arg, s_.t, bases_, k, phase, &numeric);
    if (numeric) NoteBaseValues(s_.t, true);
    return harmonic;
  }

  // The parameters bound to a known base (`frequencies: [w]`) whose value
  // `problem` uses nowhere else (METHOD.md s.19).
  std::map<std::string, int> FrequencyParameters() const {
    std::map<std::string, int> out;
    for (int i = 0; i < model_.num_bases(); ++i) {
      const std::string& name = model_.frequencies[i].parameter;
      if (name.empty() || base_value_used_[i]) continue;
      bool elsewhere = false;  // another base's value is an expression of it
      for (int j = 0; j < model_.num_bases(); ++j)
        elsewhere = elsewhere || (j != i && s_.frequency_values[j].has(s_.parameters.at(name)));
      if (!elsewhere) out[name] = i;
    }
    return out;
  }

  // ---- polynomial conversion ---------------------------------------------------------
  Polynomial Checked(Polynomial p) const {
    if (p.terms().size() > kMaxTerms)
      Fail("the recast polynomial has more than " + std::to_string(kMaxTerms) +
           " terms after expansion");
    return p;
  }

  double ConstantValue(const ex& e) const {
    for (const auto& w : unknown_bases_)
      if (e.has(w))
        Fail("the unknown base frequency '" + internal::Print(w) +
                 "' appears outside cos/sin(k*" + internal::Print(w) +
                 "*t); the solver treats a frequency only through time derivatives and forcing" +
                 (in_auxiliary_ ? std::string(" (here through the time derivative of a nonlinear "
                                              "function of a forcing term: such forcing needs a "
                                              "known frequency)")
                                : std::string()),
             internal::Print(w));
    NoteBaseValues(e, false);
    try {
      return internal::EvaluateConstant(e.subs(bases_.KnownValues()));
    } catch (const std::exception& err) {
      Fail(err.what());
    }
  }

  Polynomial P(const ex& e) const {
    if (is_a<GiNaC::numeric>(e) || IsConstant(e)) return Polynomial(ConstantValue(e));
    if (is_a<GiNaC::symbol>(e)) {
      auto it = slots_.find(e);
      if (it != slots_.end())
        return it->second.derivative ? Polynomial::Derivative(it->second.variable)
                                     : Polynomial::Variable(it->second.variable);
      if (e == s_.t)
        Fail("explicit time 't' may only appear in forcing terms cos(k*w*t), sin(k*w*t) (the "
             "response must be periodic)",
             "t");
      Fail("internal: unmapped symbol " + internal::Print(e));
    }
    if (is_a<GiNaC::add>(e)) {
      Polynomial sum;
      for (std::size_t i = 0; i < e.nops(); ++i) sum += P(e.op(i));
      return Checked(sum);
    }
    if (is_a<GiNaC::mul>(e)) {
      Polynomial product(1.0);
      for (std::size_t i = 0; i < e.nops(); ++i) product = Checked(product * P(e.op(i)));
      return product;
    }
    if (is_a<GiNaC::power>(e) && is_a<GiNaC::numeric>(e.op(1)) &&
        GiNaC::ex_to<GiNaC::numeric>(e.op(1)).is_nonneg_integer()) {
      const int n = GiNaC::ex_to<GiNaC::numeric>(e.op(1)).to_int();
      const Polynomial base = P(e.op(0));
      Polynomial r(1.0);
      for (int i = 0; i < n; ++i) r = Checked(r * base);
      return r;
    }
    if (is_a<GiNaC::function>(e) && e.nops() == 1 && FreeOfDynamic(e)) {
      const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
      std::vector<int> k;
      ex phase;
      if ((name == "sin" || name == "cos") && Harmonic(e.op(0), &k, &phase)) {
        // cos/sin of the phase symbolically first: cos(pi/2) is exactly 0.
        const double c = ConstantValue(GiNaC::cos(phase)), s = ConstantValue(GiNaC::sin(phase));
        if (name == "cos") return Polynomial::Cos(k, c) - Polynomial::Sin(k, s);
        return Polynomial::Sin(k, c) + Polynomial::Cos(k, s);
      }
      Fail(internal::Print(e) + " is not a harmonic of the base frequencies: time may only appear as " +
           "cos(k*w*t + phase), sin(k*w*t + phase) with integer k");
    }
    if (FreeOfDynamic(e))
      Fail("explicit time 't' may only appear in forcing terms cos(k*w*t), sin(k*w*t) (found " +
               internal::Print(e) + ")",
           "t");
    Fail("internal: not polynomial after the recast: " + internal::Print(e));
  }

  // ---- the original equations, pointwise ------------------------------------------------
  // The recast's chain variables and chain equations (its first ones), the
  // user equations as written, the user's conditions (on chain variables).
  void BuildOriginalProblem(RecastResult* result) const {
    // Not `problem`: what it uses of the base values is not noted.
    struct Untracked {
      bool* tracking;
      ~Untracked() { *tracking = true; }
    } untracked{&tracking_};
    tracking_ = false;
    const PolynomialSystem& full = result->problem.system;
    int num_chain_variables = 0, num_chain_equations = 0;
    for (int L : chain_) num_chain_variables += L, num_chain_equations += L - 1;
    const bool several = bases_.symbols.size() > 1;
    bool unknown = false;
    for (bool u : bases_.unknown) unknown = unknown || u;
    HarmonicBalanceProblem p;
    for (int j = 0; j < num_chain_variables; ++j)
      p.system.AddVariable(full.variables()[j].name, VariableRole::kState, full.variables()[j].definition);
    for (int i = 0; i < num_chain_equations; ++i) p.system.AddEquation(full.equations()[i].lhs);
    std::vector<ex> all;
    for (const ex& equation : s_.equations) all.push_back(Substituted(equation).subs(bases_.KnownValues()));
    internal::ShareCoulombTerms(&all);
    for (std::size_t i = 0; i < s_.equations.size(); ++i) {
      const ex& e = all[i];
      const std::string where = "equation " + std::to_string(i + 1);
      for (const auto& w : unknown_bases_)
        if (e.has(w)) return void(result->original_problem_error = where + " contains the unknown frequency");
      if (e.has(s_.t) && (several || unknown))
        return void(result->original_problem_error =
                        where + " has explicit time with " + (several ? "several base frequencies" : "an unknown frequency"));
      PointwiseEquation pointwise;
      const std::string error = MakePointwise(static_cast<int>(i), e, all, &pointwise);
      if (!error.empty()) return void(result->original_problem_error = where + ": " + error);
      p.system.AddPointwiseEquation(std::move(pointwise));
    }
    p.frequencies = result->problem.frequencies;
    p.unknown_frequency = result->problem.unknown_frequency;
    p.conditions.assign(result->problem.conditions.begin(),
                        result->problem.conditions.begin() + result->num_user_conditions);
    if (p.frequencies.size() == 1) {
      HalfTurnSymmetry half_wave{{1}, std::vector<int>(p.system.num_variables(), -1),
                                 "x -> -x with t + T/2 (odd harmonics only)"};
      try {
        for (int i = 0; i < p.system.num_equations(); ++i) half_wave.EquationSign(p.system, i, 1);
        result->original_half_wave = half_wave;
      } catch (const std::invalid_argument&) {
      }
    }
    result->original_problem = std::move(p);
  }

  // User equation i, e (parameters substituted), evaluated pointwise with
  // its exact partials in every chain slot it contains; a coulomb() term is
  // replaced by its dynamic Lagrangian (METHOD.md s.15). Returns the reason
  // when it cannot be (explicit time with an unknown or several bases, a
  // coulomb term that is not a force added to the equation, a function the
  // tape does not know).
  std::string MakePointwise(int i, ex e, const std::vector<ex>& all, PointwiseEquation* pointwise) const {
    NoteBaseValues(e, true);
    if (internal::HasCoulomb(e)) NoteBaseValues(s_.t, true);  // its penalty uses w
    // The equation whose rest sets a shared friction force (the first that
    // holds the term: DynamicLagrangian).
    ex owner = e;
    if (internal::HasCoulomb(e)) {
      GiNaC::exset terms;
      e.find(internal::coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2)), terms);
      const int first = terms.size() == 1 ? internal::CoulombOwner(all, *terms.begin()) : -1;
      if (first >= 0) owner = all[first];
      NoteBaseValues(owner, true);
    }
    owner = owner.subs(bases_.KnownValues());
    e = e.subs(bases_.KnownValues());
    bool unknown = false;
    for (bool u : bases_.unknown) unknown = unknown || u;
    if (e.has(s_.t) && (bases_.symbols.size() > 1 || unknown))
      return std::string("explicit time with ") + (unknown ? "an unknown frequency" : "several base frequencies") +
             " in a pointwise equation";
    for (const auto& w : unknown_bases_)
      if (e.has(w)) return "the unknown frequency appears outside forcing terms";
    if (internal::HasCoulomb(e)) {
      try {
        e = internal::DynamicLagrangian(e, owner, LagrangianPenalty(owner));
      } catch (const std::invalid_argument& err) {
        return err.what();
      }
    }
    std::vector<ex> inputs{s_.t}, outputs{e};
    for (std::size_t v = 0; v < chain_.size(); ++v)
      for (int j = 0; j <= chain_[v] && j < static_cast<int>(s_.derivatives[v].size()); ++j) {
        const ex& sym = s_.derivatives[v][j];
        if (!e.has(sym)) continue;
        const SlotRef ref = slots_.at(sym);
        pointwise->slots.push_back({ref.variable, ref.derivative});
        inputs.push_back(sym);
        outputs.push_back(e.diff(GiNaC::ex_to<GiNaC::symbol>(sym)));
      }
    for (const auto& b : bases_.symbols) inputs.push_back(b);
    std::shared_ptr<const CompiledFunction> tape;
    try {
      tape = std::make_shared<const CompiledFunction>(internal::Compile(outputs, inputs));
    } catch (const std::exception& err) {
      return err.what();
    }
    pointwise->evaluate = [tape](const double* in, double* out) {
      thread_local std::vector<double> work;
      tape->Evaluate(in, out, &work);
    };
    pointwise->evaluate_many = [tape](long count, const double* in, long in_stride, double* out,
                                      long out_stride) {
      thread_local std::vector<double> work;
      tape->EvaluateMany(count, in, in_stride, out, out_stride, &work);
    };
    pointwise->text = model_.equations[i].text;
    pointwise->nonsmooth = internal::HasNonSmooth(outputs[0]);
    pointwise->half_wave_sign = HalfWaveSign(*pointwise, bases_.values);
    return "";
  }

  // The automatic penalty of a dynamic Lagrangian: the equation's impedance
  // at the base frequency w from its linear part at rest, w |de/dx^(n)| +
  // |de/dx^(n-1)| summed over the variables (x^(n) the highest derivative),
  // so that eps v is of the size of the forces around it (Nacivet et al.
  // scale it with the contact stiffness). 1 when that is not positive.
  ex LagrangianPenalty(const ex& e) const {
    const ex rest = e.subs(internal::coulomb(GiNaC::wild(0), GiNaC::wild(1), GiNaC::wild(2)) == 0);
    GiNaC::exmap origin;
    for (const auto& chain : s_.derivatives)
      for (const auto& sym : chain) origin[sym] = 0;
    const double w = bases_.values.empty() ? 1.0 : bases_.values[0];
    double penalty = 0;
    try {
      for (std::size_t v = 0; v < chain_.size(); ++v) {
        const int n = chain_[v];
        if (n >= static_cast<int>(s_.derivatives[v].size())) continue;
        const auto& top = s_.derivatives[v][n];
        const auto& below = s_.derivatives[v][n - 1];
        penalty += w * std::abs(internal::EvaluateConstant(rest.diff(top).subs(origin).subs(s_.t == 0)));
        penalty += std::abs(internal::EvaluateConstant(rest.diff(below).subs(origin).subs(s_.t == 0)));
      }
    } catch (const std::exception&) {
      penalty = 0;
    }
    return penalty > 0 && std::isfinite(penalty) ? ex(penalty) : ex(1);
  }

  // g(t + T/2, -z) = +-g(t, z): +1 or -1, 0 when not (or with several bases).
  static int HalfWaveSign(const PointwiseEquation& e, const std::vector<double>& w) {
    if (w.size() != 1 || !(w[0] > 0)) return 0;
    return PointwiseEquationSign(e, w, 1, M_PI / w[0], std::vector<int>(e.slots.size(), -1));
  }

  // ---- conditions -------------------------------------------------------------------
  PointCondition MakeCondition(const ex& residual, const std::string& description) {
    ex r = residual;
    if (r.has(s_.t)) r = r.subs(s_.t == 0);
    for (const auto& w : unknown_bases_)
      if (r.has(w)) Fail("a condition cannot depend on the unknown base frequency '" + internal::Print(w) + "'");
    NoteBaseValues(r, false);
    r = r.subs(bases_.KnownValues());
    // Inputs: the symbols present, mapped to z(0) or z'(0).
    std::vector<ex> inputs;
    std::vector<SlotRef> refs;
    for (const auto& [sym, ref] : slots_)
      if (r.has(sym)) {
        inputs.push_back(sym);
        refs.push_back(ref);
      }
    for (const auto& [sym, ref] : user_sym_)
      if (r.has(sym) && !slots_.count(sym))
        Fail("'" + internal::Print(sym) + "' at t = 0 is beyond the states of the recast system");
    std::vector<ex> outputs{r};
    for (const ex& in : inputs) outputs.push_back(r.diff(GiNaC::ex_to<GiNaC::symbol>(in)));
    std::shared_ptr<const CompiledFunction> tape;
    try {
      tape = std::make_shared<const CompiledFunction>(internal::Compile(outputs, inputs));
    } catch (const std::exception& err) {
      Fail(err.what());
    }
    PointCondition c;
    c.description = description;
    // Called once per residual evaluation: the thread's own buffers keep it
    // thread-safe without three allocations per call.
    c.function = [tape, refs](const Eigen::VectorXd& z, const Eigen::VectorXd& dz,
                              Eigen::VectorXd* gz, Eigen::VectorXd* gdz) {
      thread_local std::vector<double> in, out, work;
      in.resize(refs.size());
      out.resize(refs.size() + 1);
      for (std::size_t i = 0; i < refs.size(); ++i)
        in[i] = refs[i].derivative ? dz(refs[i].variable) : z(refs[i].variable);
      tape->Evaluate(in.data(), out.data(), &work);
      for (std::size_t i = 0; i < refs.size(); ++i) {
        Eigen::VectorXd* g = refs[i].derivative ? gdz : gz;
        if (g) (*g)(refs[i].variable) += out[i + 1];
      }
      return out[0];
    };
    return c;
  }

  // ---- guess --------------------------------------------------------------------------
  // The guess is evaluated numerically in sequence: the user variables and
  // their derivatives (symbolic derivatives of the guess expressions) from the
  // angles, then each auxiliary's definition on the values before it. A guess
  // outside a definition's domain (log of a negative value, 1/0) gives a
  // non-finite value that InitialGuess reports, instead of failing here.
  // Sets result->guess and result->variables_from_user (the guess is the
  // latter on the guessed user values).
  void BuildGuess(const PolynomialSystem& system, RecastResult* result) {
    const int d = static_cast<int>(bases_.symbols.size());
    std::vector<GiNaC::symbol> angles;
    for (int i = 0; i < d; ++i) angles.emplace_back("theta" + std::to_string(i + 1));
    // Inputs of every tape: the angles, the user derivative symbols, the
    // auxiliaries; outputs of the first tape: the user derivative values.
    std::vector<ex> inputs(angles.begin(), angles.end());
    std::vector<ex> user_values;
    std::vector<int> output_variable;  // recast variable of each user value, or -1
    std::vector<SlotRef> user_slots;   // where each user value lives in a solution
    result->user_derivatives.clear();
    for (std::size_t v = 0; v < chain_.size(); ++v) {
      ex g = Substituted(s_.guess[v]);
      result->user_derivatives.push_back(chain_[v]);
      for (int j = 0; j <= chain_[v]; ++j) {
        const ex& sym = s_.derivatives[v][j];
        inputs.push_back(sym);
        user_values.push_back(g);
        const SlotRef ref = slots_.at(sym);
        output_variable.push_back(ref.derivative ? -1 : ref.variable);
        user_slots.push_back(ref);
        g = g.diff(s_.t);
      }
    }
    for (const auto& a : aux_) inputs.push_back(a.sym);
    struct Guess {
      CompiledFunction user;
      std::vector<CompiledFunction> aux;
      std::vector<int> output_variable;
      std::vector<int> aux_variable;
      int num_angles, num_inputs, num_variables;
    };
    auto guess = std::make_shared<Guess>();
    try {
      std::vector<ex> angle_inputs(angles.begin(), angles.end());
      for (auto& u : user_values) u = internal::ToAngles(u, s_.t, bases_, angles);
      guess->user = internal::Compile(user_values, angle_inputs);
      for (const auto& a : aux_) {
        guess->aux.push_back(
            internal::Compile({internal::ToAngles(a.definition, s_.t, bases_, angles)}, inputs));
        guess->aux_variable.push_back(a.index);
      }
    } catch (const ModelError&) {
      throw;
    } catch (const std::exception& err) {
      throw ModelError(std::string("cannot build the initial guess: ") + err.what(),
                       model_.guess.empty() ? SourceLocation{model_.source, 0, 0}
                                            : model_.guess.front().second.where);
    }
    guess->output_variable = output_variable;
    guess->num_angles = d;
    guess->num_inputs = static_cast<int>(inputs.size());
    guess->num_variables = system.num_variables();
    auto from_user = [guess](const std::vector<double>& theta, const std::vector<double>& values) {
      if (theta.size() != static_cast<std::size_t>(guess->num_angles) ||
          values.size() != guess->output_variable.size())
        throw std::invalid_argument("variables_from_user: wrong number of angles or user values");
      std::vector<double> in(guess->num_inputs), work;
      for (int i = 0; i < guess->num_angles; ++i) in[i] = theta[i];
      double* user = in.data() + guess->num_angles;
      for (std::size_t k = 0; k < values.size(); ++k) user[k] = values[k];
      Eigen::VectorXd out = Eigen::VectorXd::Zero(guess->num_variables);
      for (std::size_t k = 0; k < guess->output_variable.size(); ++k)
        if (guess->output_variable[k] >= 0) out(guess->output_variable[k]) = user[k];
      double* aux = user + guess->output_variable.size();
      for (std::size_t a = 0; a < guess->aux.size(); ++a) {
        guess->aux[a].Evaluate(in.data(), aux + a, &work);
        out(guess->aux_variable[a]) = aux[a];
      }
      return out;
    };
    result->variables_from_user = from_user;
    // The check of a solution against the definitions: the user values read
    // off the solution (a value, or the derivative of the chain's top state).
    result->problem.definitions.derivatives = 1;
    result->problem.definitions.evaluate = [user_slots, from_user](
                                               const std::vector<double>& theta,
                                               const std::vector<Eigen::VectorXd>& z) {
      std::vector<double> user(user_slots.size());
      for (std::size_t k = 0; k < user_slots.size(); ++k)
        user[k] = z[user_slots[k].derivative](user_slots[k].variable);
      return from_user(theta, user);
    };
    result->guess = [guess, from_user](const std::vector<double>& theta) {
      std::vector<double> user(guess->output_variable.size()), work;
      guess->user.Evaluate(theta.data(), user.data(), &work);
      return from_user(theta, user);
    };
  }

  std::optional<std::vector<double>> InitialState(const OriginalSystem& original) const {
    std::vector<double> state(original.dimension, 0.0);
    std::vector<bool> set(original.dimension, false);
    auto position = [&](int v, int j) {
      int p = 0;
      for (int u = 0; u < v; ++u) p += std::max(model_.orders[u], 1);
      return p + j;
    };
    if (!s_.initial_state.empty()) {
      for (std::size_t i = 0; i < s_.initial_state.size(); ++i) {
        const auto& [vj, value] = s_.initial_state[i];
        const SourceLocation& where = model_.initial_state[i].second.where;
        double x;
        try {
          x = internal::EvaluateConstant(Substituted(value).subs(bases_.AllValues()));
        } catch (const std::exception& err) {
          throw ModelError(std::string(err.what()) + " in initial_state", where);
        }
        state[position(vj.first, vj.second)] = x;
        set[position(vj.first, vj.second)] = true;
      }
      // Algebraic states may be left out: IDACalcIC computes them.
      for (int i = 0; i < original.dimension; ++i)
        if (!set[i] && original.differential[i])
          throw ModelError("initial_state does not give '" + original.state_names[i] + "'",
                           model_.initial_state.front().second.where, original.state_names[i]);
      return state;
    }
    // From conditions of the form x^(j)(0) = constant.
    for (const ex& c : s_.conditions) {
      const ex r = Substituted(c).subs(bases_.KnownValues());
      for (std::size_t v = 0; v < chain_.size(); ++v)
        for (int j = 0; j < std::max(model_.orders[v], 1); ++j) {
          const ex& sym = s_.derivatives[v][j];
          if (!r.has(sym)) continue;
          const ex coefficient = r.diff(GiNaC::ex_to<GiNaC::symbol>(sym));
          const ex rest = (r - coefficient * sym).expand();
          if (!IsConstant(coefficient) || !IsConstant(rest) || coefficient.is_zero()) continue;
          try {
            state[position(v, j)] = internal::EvaluateConstant(-rest / coefficient);
            set[position(v, j)] = true;
          } catch (const std::exception&) {
          }
        }
    }
    for (int i = 0; i < original.dimension; ++i)
      if (!set[i] && original.differential[i]) return std::nullopt;
    return state;
  }

  const ModelDefinition& model_;
  const SymbolicModel& s_;
  const bool problem_only_;  // `problem`, its definitions and the guess only
  ParameterValues values_;
  internal::Bases bases_;
  GiNaC::exmap params_;
  std::vector<int> chain_;  // states per user variable (x, x_d1, ...)
  ExSet dynamic_;
  ExSet unknown_bases_;
  ExMap<SlotRef> user_sym_;  // user derivative symbol -> (variable, order)
  ExMap<SlotRef> slots_;
  std::vector<Aux> aux_;
  std::vector<PendingEquation> equations_;
  ExMap<ex> cache_;  // original subexpression -> recast
  std::map<RuleKey, ex, RuleKeyLess> memo_;  // (rule, recast argument) -> auxiliary
  std::map<std::string, int> counter_;
  std::set<std::string> taken_;
  int source_ = -1;
  int condition_ = -1;
  bool in_auxiliary_ = false;  // converting an auxiliary's equation
  mutable bool tracking_ = true;  // noting base values for `problem`
  mutable std::vector<bool> base_value_used_;  // per base, by `problem`
};

}  // namespace

HarmonicSolution RecastResult::InitialGuess(const HarmonicBasis& basis) const {
  HarmonicSolution s = HarmonicSolution::FromAngles(basis, problem.frequencies,
                                                    problem.system.variables(), guess);
  const Eigen::MatrixXd& c = s.coefficients();
  for (int j = 0; j < c.rows(); ++j)
    if (!c.row(j).allFinite())
      throw ModelError("the initial guess of '" + problem.system.variables()[j].name +
                           "' is not finite (" +
                           (problem.system.variables()[j].definition.empty()
                                ? std::string("check the guess")
                                : "= " + problem.system.variables()[j].definition +
                                      " on the guessed states") +
                           ")",
                       {source, 0, 0}, problem.system.variables()[j].name);
  return s;
}

HarmonicSolution RecastResult::InitialGuess(int order, BasisShape shape) const {
  HarmonicBalanceOptions options;
  options.order = order;
  options.shape = shape;
  return InitialGuess(MakeBasis(static_cast<int>(problem.frequencies.size()), options));
}

std::string RecastResult::Report() const {
  std::ostringstream out;
  out.precision(12);
  out << "model " << model_name << "\n";
  if (!parameters.empty()) {
    out << "parameters:";
    for (const auto& [name, value] : parameters) out << " " << name << " = " << value;
    out << "\n";
  }
  out << "base frequencies:";
  for (std::size_t i = 0; i < problem.frequencies.size(); ++i) {
    const bool unknown = !problem.unknown_frequency.empty() && problem.unknown_frequency[i];
    out << " " << problem.frequencies[i] << (unknown ? " (unknown, guess)" : " (known)");
  }
  out << "\n";
  if (!definitions.empty()) {
    out << "auxiliary variables:\n";
    for (const auto& d : definitions) out << "  " << d << "\n";
  }
  out << problem.system.ToString();
  out << "degree phi = " << degree << "\n";
  if (!problem.conditions.empty()) {
    out << "conditions at t = 0:\n";
    for (const auto& c : problem.conditions) out << "  " << c.description << "\n";
  }
  return out.str();
}

RecastResult Recast(const ModelDefinition& model, const ParameterValues& overrides, bool problem_only) {
  if (!model.symbolic) throw ModelError("Recast: the model was not parsed", {model.source, 0, 0});
  try {
    Recaster recaster(model, overrides, problem_only);
    return recaster.Run();
  } catch (const ModelError&) {
    throw;
  } catch (const std::exception& e) {
    throw ModelError(std::string("cannot recast the model: ") + e.what(), {model.source, 0, 0});
  }
}

}  // namespace rmhb::model
