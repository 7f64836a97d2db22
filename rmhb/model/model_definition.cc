#include "rmhb/model/model_definition.h"

#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/exact_numbers.h"
#include "rmhb/model/internal/expression_parser.h"
#include "rmhb/model/internal/symbolic_model.h"

namespace rmhb::model {
namespace {

using GiNaC::ex;
using internal::ParseError;
using internal::SymbolicModel;

constexpr int kMaxPrimes = 8;

std::string Plural(std::size_t n, const std::string& word) {
  return std::to_string(n) + " " + word + (n == 1 ? "" : "s");
}

std::string Join(const std::vector<std::string>& names) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i) s += (i ? ", " : "") + names[i];
  return s;
}

std::string Primes(int n) { return std::string(static_cast<std::size_t>(n), '\''); }

class Loader {
 public:
  Loader(const std::string& text, const std::string& source, const std::vector<std::string>& added_conditions,
         const std::string& frequency_guess)
      : text_(text),
        added_conditions_(added_conditions),
        frequency_guess_(frequency_guess),
        symbolic_(std::make_shared<SymbolicModel>()) {
    model_.source = source;
    model_.text = text;
  }

  ModelDefinition Load() {
    YAML::Node root = YAML::Load(text_);
    if (!root || root.IsNull())
      throw ModelError("empty model: expected a YAML map with variables, equations, frequencies",
                       {model_.source, 1, 1});
    if (!root.IsMap())
      throw ModelError("a model must be a YAML map (keys name, variables, parameters, equations, "
                       "frequencies, ...)",
                       Where(root));
    static const std::set<std::string> keys = {"name",       "description", "variables",
                                               "parameters", "equations",   "frequencies",
                                               "conditions", "initial_state", "guess"};
    std::set<std::string> seen;
    for (const auto& kv : root) {
      if (!kv.first.IsScalar()) throw ModelError("keys of the model map must be names", Where(kv.first));
      const std::string key = kv.first.Scalar();
      if (!keys.count(key))
        throw ModelError("unknown key '" + key +
                             "' (expected name, description, variables, parameters, equations, "
                             "frequencies, conditions, initial_state, guess)",
                         Where(kv.first), key);
      if (!seen.insert(key).second) throw ModelError("duplicate key '" + key + "'", Where(kv.first), key);
    }

    if (root["name"]) model_.name = ScalarString(root["name"], "name");
    if (model_.name.empty()) {
      std::string base = model_.source;
      if (auto slash = base.find_last_of('/'); slash != std::string::npos) base = base.substr(slash + 1);
      if (auto dot = base.rfind('.'); dot != std::string::npos && dot > 0) base = base.substr(0, dot);
      model_.name = base;
    }
    if (root["description"]) model_.description = ScalarString(root["description"], "description");

    LoadVariables(root["variables"], Where(root));
    LoadParameters(root["parameters"]);
    YAML::Node frequencies = root["frequencies"];
    if (!frequencies || frequencies.IsNull())
      frequencies = FrequencyFromForcing(root["equations"], Where(root));
    LoadFrequencies(frequencies);
    LoadEquations(root["equations"], Where(root));
    LoadConditions(root["conditions"]);
    LoadInitialState(root["initial_state"]);
    LoadGuess(root["guess"]);
    model_.symbolic = symbolic_;
    return model_;
  }

 private:
  SourceLocation Where(const YAML::Node& node) const {
    const YAML::Mark m = node.Mark();
    if (m.line < 0) return {model_.source, 0, 0};
    return {model_.source, m.line + 1, m.column + 1};
  }

  // Where the text of a scalar starts, and whether offsets into its value map
  // to columns (single-line plain or quoted scalars).
  SourceLocation TextStart(const YAML::Node& node, bool* maps_offsets) const {
    SourceLocation w = Where(node);
    const YAML::Mark m = node.Mark();
    *maps_offsets = false;
    if (m.pos < 0 || static_cast<std::size_t>(m.pos) >= text_.size()) return w;
    const char c = text_[static_cast<std::size_t>(m.pos)];
    if (c == '|' || c == '>') return w;
    const std::string& value = node.Scalar();
    if (value.find('\n') != std::string::npos) return w;
    if (c == '"' || c == '\'') w.column += 1;
    *maps_offsets = true;
    return w;
  }

  std::string ScalarString(const YAML::Node& node, const std::string& what) const {
    if (!node.IsScalar()) throw ModelError("'" + what + "' must be a string", Where(node), what);
    return node.Scalar();
  }

  // Parses a scalar expression/equation, mapping parse errors to the file.
  ex ParseScalar(const YAML::Node& node, const std::string& context, bool equation,
                 const internal::Resolver& resolver, SourceText* text) {
    if (!node.IsScalar())
      throw ModelError("expected a string with an expression " + context, Where(node));
    bool maps = false;
    const SourceLocation start = TextStart(node, &maps);
    text->text = node.Scalar();
    text->where = start;
    try {
      return equation ? internal::ParseEquation(text->text, resolver)
                      : internal::ParseExpression(text->text, resolver);
    } catch (const ParseError& e) {
      SourceLocation at = maps ? start.Shifted(static_cast<int>(e.offset)) : start;
      throw ModelError(e.message + " " + context, at, e.symbol);
    }
  }

  bool IsReserved(const std::string& name) const {
    return name == "t" || name == "pi" || internal::IsBuiltinFunctionName(name) ||
           internal::IsNonSmoothFunctionName(name);
  }

  void LoadVariables(const YAML::Node& node, const SourceLocation& root) {
    if (!node) throw ModelError("missing 'variables' (the list of unknown functions of t)", root);
    std::vector<YAML::Node> items;
    if (node.IsScalar()) items.push_back(node);
    else if (node.IsSequence())
      for (const auto& n : node) items.push_back(n);
    else throw ModelError("'variables' must be a list of names, e.g. [x, y]", Where(node));
    if (items.empty()) throw ModelError("'variables' is empty", Where(node));
    if (items.size() > 64) throw ModelError("too many variables (at most 64)", Where(node));
    for (const auto& item : items) {
      if (!item.IsScalar()) throw ModelError("a variable must be a name", Where(item));
      const std::string name = item.Scalar();
      if (!internal::IsValidIdentifier(name))
        throw ModelError("'" + name + "' is not a valid variable name (letters, digits, _)",
                         Where(item), name);
      const bool frequency_symbol =
          name == "w" || (name.size() > 1 && name[0] == 'w' && name.find_first_not_of("0123456789", 1) == std::string::npos);
      if (IsReserved(name) || frequency_symbol)
        throw ModelError("'" + name + "' is reserved and cannot be a variable name" +
                             (frequency_symbol ? " (w, w1, w2, ... are the base frequencies in guesses and "
                                                 "conditions): rename it, e.g. " + name + "_"
                                               : std::string()),
                         Where(item), name);
      if (model_.IndexOfVariable(name) >= 0)
        throw ModelError("variable '" + name + "' declared twice", Where(item), name);
      model_.variables.push_back(name);
      variable_where_.push_back(Where(item));
      std::vector<GiNaC::symbol> d;
      for (int j = 0; j <= kMaxPrimes + 2; ++j) d.emplace_back(name + Primes(j));
      symbolic_->derivatives.push_back(std::move(d));
    }
    model_.orders.assign(model_.variables.size(), 0);
  }

  void LoadParameters(const YAML::Node& node) {
    if (!node || node.IsNull()) return;
    if (!node.IsMap()) throw ModelError("'parameters' must be a map name: value", Where(node));
    for (const auto& kv : node) {
      if (!kv.first.IsScalar()) throw ModelError("a parameter name must be a name", Where(kv.first));
      const std::string name = kv.first.Scalar();
      if (!internal::IsValidIdentifier(name))
        throw ModelError("'" + name + "' is not a valid parameter name", Where(kv.first), name);
      if (IsReserved(name))
        throw ModelError("'" + name + "' is reserved and cannot be a parameter name", Where(kv.first),
                         name);
      if (model_.IndexOfVariable(name) >= 0)
        throw ModelError("'" + name + "' is both a variable and a parameter", Where(kv.first), name);
      if (model_.FindParameter(name))
        throw ModelError("parameter '" + name + "' defined twice", Where(kv.first), name);
      if (!kv.second.IsScalar())
        throw ModelError("parameter '" + name + "' must be a number", Where(kv.second), name);
      GiNaC::numeric exact;
      std::string why;
      const std::string value = kv.second.Scalar();
      if (!internal::DecimalToRational(value, &exact, &why))
        throw ModelError("parameter '" + name + "' must be a finite number, got '" + value + "'",
                         Where(kv.second), name);
      const double d = exact.to_double();
      if (!std::isfinite(d))
        throw ModelError("parameter '" + name + "' is not finite", Where(kv.second), name);
      model_.parameters.push_back({name, d, Where(kv.first)});
      symbolic_->parameters.emplace(name, GiNaC::symbol(name));
    }
  }

  // Resolution of names common to every kind of expression.
  bool ResolveCommon(const std::string& name, int primes, std::size_t offset, ex* out,
                     bool allow_bases) const {
    auto param = symbolic_->parameters.find(name);
    if (param != symbolic_->parameters.end()) {
      if (primes) throw ParseError{offset, "'" + name + "' is a parameter: it has no derivative", name};
      *out = param->second;
      return true;
    }
    if (name == "pi") {
      if (primes) throw ParseError{offset, "pi has no derivative", name};
      *out = GiNaC::Pi;
      return true;
    }
    if (allow_bases) {
      const int d = static_cast<int>(symbolic_->bases.size());
      int index = -1;
      if (name == "w" && d == 1) index = 0;
      if (name.size() > 1 && name[0] == 'w' &&
          name.find_first_not_of("0123456789", 1) == std::string::npos && name.size() < 4) {
        const int k = std::stoi(name.substr(1));
        if (k >= 1 && k <= d) index = k - 1;
      }
      if (index >= 0) {
        if (primes) throw ParseError{offset, "'" + name + "' is a base frequency: it has no derivative", name};
        *out = symbolic_->bases[index];
        return true;
      }
    }
    return false;
  }

  std::string UnknownSymbolMessage(const std::string& name, const std::string& context) const {
    std::string msg = "unknown symbol '" + name + "'";
    if (name == "w" && symbolic_->bases.size() > 1) msg += " (with several bases write w1, w2, ...)";
    else if (name.size() > 1 && name[0] == 'w' &&
             name.find_first_not_of("0123456789", 1) == std::string::npos)
      msg += " (the model has " + Plural(symbolic_->bases.size(), "base frequency") + ")";
    (void)context;
    return msg;
  }

  // A file without 'frequencies' (rmhb/METHOD.md s.20): a forced model's one
  // base is read off its forcing. Every t in the equations must sit in a sin
  // or cos of a t + b, a and b of the parameters only; the smallest |a| is
  // the base when every other a is an integer multiple of it (cos(w t) and
  // sin(3 w t): w). A parameter that is the base stays one (--set w,
  // --continue w). No t at all (an autonomous model): one unknown base,
  // whose guess the loader reads off the trajectory from initial_state, or
  // from next to rest without one (frequency_from_trajectory;
  // rmhb/pipeline/model.h) and passes back as frequency_guess. Anything else
  // (t outside a sinusoid; incommensurate a) asks for 'frequencies'.
  YAML::Node FrequencyFromForcing(const YAML::Node& equations, const SourceLocation& root) {
    const std::string missing =
        "missing 'frequencies': give each base frequency, a number if known or {guess: value} if it is "
        "solved for";
    if (!equations || !(equations.IsSequence() || equations.IsScalar())) throw ModelError(missing, root);
    std::vector<ex> rates;
    bool only_sinusoids = true;
    internal::Resolver resolver;
    resolver.symbol = [&](const std::string& name, int primes, std::size_t offset) -> ex {
      const int v = model_.IndexOfVariable(name);
      if (v >= 0 && primes < static_cast<int>(symbolic_->derivatives[v].size()))
        return symbolic_->derivatives[v][primes];
      if (name == "t") return symbolic_->t;
      ex out;
      if (ResolveCommon(name, primes, offset, &out, false)) return out;
      throw ParseError{offset, "", name};
    };
    std::vector<YAML::Node> items;
    if (equations.IsSequence())
      for (const auto& n : equations) items.push_back(n);
    else items.push_back(equations);
    for (const YAML::Node& item : items) {
      if (!item.IsScalar()) throw ModelError(missing, root);
      try {
        CollectRates(internal::ParseEquation(item.Scalar(), resolver), &rates, &only_sinusoids);
      } catch (const ParseError&) {
        throw ModelError(missing, root);  // LoadEquations would say why; the frequencies come first
      }
    }
    const GiNaC::exmap defaults = ParameterDefaults();
    int base = -1;
    std::vector<double> values;
    for (const ex& a : rates) {
      double value = 0;
      try {
        value = std::abs(internal::EvaluateConstant(a.subs(defaults)));
      } catch (const std::exception&) {
        only_sinusoids = false;
      }
      if (!(value > 0)) only_sinusoids = false;
      values.push_back(value);
      if (base < 0 || value < values[base]) base = static_cast<int>(values.size()) - 1;
    }
    if (rates.empty() && only_sinusoids) {
      model_.frequency_from_trajectory = frequency_guess_.empty();
      model_.frequency_guess = frequency_guess_;
      YAML::Node node;
      node["guess"] = frequency_guess_.empty() ? std::string("1") : frequency_guess_;
      return node;
    }
    if (rates.empty() || !only_sinusoids)
      throw ModelError(missing + " (the equations' t is not only in sin(a*t + b) or cos(a*t + b) of "
                                 "commensurate rates a, from which it could be read)",
                       root);
    for (double v : values)
      if (std::abs(v / values[base] - std::round(v / values[base])) > 1e-12)
        throw ModelError(missing + " (the forcing's rates are not integer multiples of the smallest: give "
                                   "each base)",
                         root);
    std::ostringstream printed;
    const ex a = rates[base];
    printed << (internal::EvaluateConstant(a.subs(defaults)) < 0 ? ex(-a) : a);
    // Back into the file's own notation: GiNaC prints pi as Pi.
    std::string text = printed.str();
    if (!symbolic_->parameters.count("Pi"))
      for (std::size_t at = text.find("Pi"); at != std::string::npos; at = text.find("Pi", at + 2)) {
        const bool alone = (at == 0 || !std::isalnum(static_cast<unsigned char>(text[at - 1]))) &&
                           (at + 2 == text.size() || !std::isalnum(static_cast<unsigned char>(text[at + 2])));
        if (alone) text[at] = 'p';
      }
    YAML::Node node;
    node.push_back(text);
    return node;
  }

  // The rates a of every sin(a t + b) and cos(a t + b) in e; only_sinusoids
  // turns false at a t anywhere else.
  void CollectRates(const ex& e, std::vector<ex>* rates, bool* only_sinusoids) const {
    const ex& t = symbolic_->t;
    if (!e.has(t)) return;
    if (e.is_equal(t)) {
      *only_sinusoids = false;
      return;
    }
    if (GiNaC::is_a<GiNaC::function>(e)) {
      const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
      const ex arg = e.op(0);
      if ((name == "sin" || name == "cos") && arg.is_polynomial(t) && arg.degree(t) == 1) {
        const ex a = arg.coeff(t, 1);
        bool constant = !a.has(t) && !arg.coeff(t, 0).has(t);
        for (const auto& v : symbolic_->derivatives)
          for (const GiNaC::symbol& z : v) constant = constant && !a.has(z) && !arg.coeff(t, 0).has(z);
        if (constant) {
          rates->push_back(a);
          return;
        }
      }
      *only_sinusoids = false;
      return;
    }
    for (std::size_t i = 0; i < e.nops(); ++i) CollectRates(e.op(i), rates, only_sinusoids);
  }

  // node: the file's 'frequencies', or FrequencyFromForcing's when it has none.
  void LoadFrequencies(const YAML::Node& node) {
    std::vector<YAML::Node> items;
    if (node.IsSequence())
      for (const auto& n : node) items.push_back(n);
    else items.push_back(node);
    if (items.empty()) throw ModelError("'frequencies' is empty", Where(node));
    if (items.size() > 4) throw ModelError("at most 4 base frequencies are supported", Where(node));
    const int d = static_cast<int>(items.size());
    // First the symbols (a frequency may be a parameter).
    std::vector<YAML::Node> values;
    for (int i = 0; i < d; ++i) {
      const YAML::Node& item = items[i];
      FrequencyDefinition f;
      YAML::Node value = item;
      if (item.IsMap()) {
        if (item.size() != 1)
          throw ModelError("a frequency entry is a number, a parameter name, {guess: value} or "
                           "{value: value}",
                           Where(item));
        const auto kv = *item.begin();
        const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
        if (key == "guess") f.unknown = true;
        else if (key != "value")
          throw ModelError("unknown key '" + key + "' in a frequency entry (expected guess or value)",
                           Where(kv.first), key);
        value = kv.second;
      }
      if (!value.IsScalar())
        throw ModelError("a frequency must be a number or an expression of the parameters",
                         Where(value));
      const std::string text = value.Scalar();
      if (!f.unknown && symbolic_->parameters.count(text)) {
        f.parameter = text;
        f.symbol = text;
        symbolic_->bases.push_back(symbolic_->parameters.at(text));
      } else {
        f.symbol = d == 1 ? "w" : "w" + std::to_string(i + 1);
        symbolic_->bases.emplace_back(f.symbol);
      }
      model_.frequencies.push_back(f);
      values.push_back(value);
    }
    // Then the values: expressions of the parameters.
    internal::Resolver resolver;
    resolver.symbol = [this](const std::string& name, int primes, std::size_t offset) -> ex {
      ex out;
      if (ResolveCommon(name, primes, offset, &out, false)) return out;
      throw ParseError{offset, UnknownSymbolMessage(name, ""), name};
    };
    for (int i = 0; i < d; ++i) {
      const std::string context = "in frequency " + std::to_string(i + 1);
      ex value = ParseScalar(values[i], context, false, resolver,
                             &model_.frequencies[i].value);
      symbolic_->frequency_values.push_back(value);
      CheckFrequency(value, model_.frequencies[i].value.where, context);
    }
  }

  // Every parameter at its file value, as an exact rational.
  GiNaC::exmap ParameterDefaults() const {
    GiNaC::exmap defaults;
    for (const auto& p : model_.parameters)
      defaults[symbolic_->parameters.at(p.name)] = internal::RationalFromDouble(p.value);
    return defaults;
  }

  void CheckFrequency(const ex& value, const SourceLocation& where, const std::string& context) {
    const GiNaC::exmap defaults = ParameterDefaults();
    double w = 0;
    try {
      w = internal::EvaluateConstant(value.subs(defaults));
    } catch (const std::exception& e) {
      throw ModelError(std::string(e.what()) + " " + context, where);
    }
    if (!(w > 0)) throw ModelError("a base frequency must be > 0 " + context, where);
  }

  void LoadEquations(const YAML::Node& node, const SourceLocation& root) {
    if (!node || node.IsNull()) throw ModelError("missing 'equations'", root);
    std::vector<YAML::Node> items;
    if (node.IsSequence())
      for (const auto& n : node) items.push_back(n);
    else if (node.IsScalar()) items.push_back(node);
    else throw ModelError("'equations' must be a list of strings", Where(node));
    const std::size_t n = model_.variables.size();
    if (items.size() != n)
      throw ModelError(Plural(items.size(), "equation") + " for " + Plural(n, "variable") + " (" +
                           Join(model_.variables) + "): give one equation per variable",
                       Where(node));
    std::vector<bool> used(n, false);
    for (std::size_t i = 0; i < items.size(); ++i) {
      const std::string context = "in equation " + std::to_string(i + 1);
      std::vector<bool> here(n, false);
      internal::Resolver resolver;
      resolver.symbol = [&](const std::string& name, int primes, std::size_t offset) -> ex {
        const int v = model_.IndexOfVariable(name);
        if (v >= 0) {
          here[v] = true;
          model_.orders[v] = std::max(model_.orders[v], primes);
          return symbolic_->derivatives[v][primes];
        }
        if (name == "t") {
          if (primes) throw ParseError{offset, "t has no derivative", name};
          return symbolic_->t;
        }
        ex out;
        if (ResolveCommon(name, primes, offset, &out, true)) return out;
        throw ParseError{offset, UnknownSymbolMessage(name, context), name};
      };
      SourceText text;
      ex e = ParseScalar(items[i], context, true, resolver, &text);
      if (e.is_zero()) throw ModelError("equation " + std::to_string(i + 1) + " is identically zero", text.where);
      bool any = false;
      for (std::size_t v = 0; v < n; ++v) {
        any = any || here[v];
        used[v] = used[v] || here[v];
      }
      if (!any)
        throw ModelError("equation " + std::to_string(i + 1) + " involves no variable", text.where);
      model_.equations.push_back(text);
      symbolic_->equations.push_back(e);
    }
    for (std::size_t v = 0; v < n; ++v)
      if (!used[v])
        throw ModelError("variable '" + model_.variables[v] + "' appears in no equation",
                         variable_where_[v], model_.variables[v]);
  }

  void LoadConditions(const YAML::Node& node) {
    std::vector<YAML::Node> items;
    if (node && !node.IsNull()) {
      if (node.IsSequence())
        for (const auto& n : node) items.push_back(n);
      else if (node.IsScalar()) items.push_back(node);
      else throw ModelError("'conditions' must be a list of strings like \"x(0) = 1\"", Where(node));
    }
    // The defaults ModelFromDefinition chose (no place in the file).
    for (const std::string& text : added_conditions_) items.push_back(YAML::Node(text));
    for (std::size_t i = 0; i < items.size(); ++i) {
      const std::string context = "in condition " + std::to_string(i + 1);
      bool any = false;
      internal::Resolver resolver;
      resolver.symbol = [&](const std::string& name, int primes, std::size_t offset) -> ex {
        if (model_.IndexOfVariable(name) >= 0)
          throw ParseError{offset,
                           "write " + name + Primes(primes) + "(0): conditions hold at t = 0", name};
        if (name == "t") throw ParseError{offset, "conditions hold at t = 0: 't' is not allowed", name};
        ex out;
        if (ResolveCommon(name, primes, offset, &out, true)) return out;
        throw ParseError{offset, UnknownSymbolMessage(name, context), name};
      };
      resolver.call = [&](const std::string& name, int primes, const std::vector<ex>& args,
                          std::size_t offset) -> ex {
        const int v = model_.IndexOfVariable(name);
        if (v < 0) {
          ex dummy;
          if (primes == 0 && !ResolveCommon(name, 0, offset, &dummy, true))
            throw ParseError{offset, "unknown function '" + name + "'", name};
          throw ParseError{offset, "'" + name + "' is not a function (write products with *)", name};
        }
        if (args.size() != 1 || !args[0].is_zero())
          throw ParseError{offset, "conditions hold at t = 0: write " + name + Primes(primes) + "(0)",
                           name};
        const int top = std::max(model_.orders[v], 1);
        if (primes > top)
          throw ParseError{offset,
                           name + Primes(primes) + "(0) is beyond the highest derivative of " + name +
                               " in the equations",
                           name};
        any = true;
        return symbolic_->derivatives[v][primes];
      };
      SourceText text;
      ex e = ParseScalar(items[i], context, true, resolver, &text);
      if (!any) throw ModelError("condition " + std::to_string(i + 1) + " involves no variable", text.where);
      model_.conditions.push_back(text);
      symbolic_->conditions.push_back(e);
    }
  }

  internal::Resolver ConstantResolver(const std::string& context) const {
    internal::Resolver resolver;
    resolver.symbol = [this, context](const std::string& name, int primes, std::size_t offset) -> ex {
      ex out;
      if (ResolveCommon(name, primes, offset, &out, true)) return out;
      if (model_.IndexOfVariable(name) >= 0 || name == "t")
        throw ParseError{offset, "'" + name + "' is not allowed here: expected an expression of the parameters", name};
      throw ParseError{offset, UnknownSymbolMessage(name, context), name};
    };
    return resolver;
  }

  void LoadInitialState(const YAML::Node& node) {
    if (!node || node.IsNull()) return;
    if (!node.IsMap())
      throw ModelError("'initial_state' must be a map like {x: 1, \"x'\": 0}", Where(node));
    std::set<std::string> seen;
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
      std::string name = key;
      int primes = 0;
      while (!name.empty() && name.back() == '\'') {
        name.pop_back();
        ++primes;
      }
      const int v = model_.IndexOfVariable(name);
      if (v < 0)
        throw ModelError("unknown variable '" + key + "' in initial_state", Where(kv.first), key);
      const int order = model_.orders[v];
      if (primes >= std::max(order, 1))
        throw ModelError("initial_state '" + key + "': the state of " + name + " is " + name +
                             (order > 1 ? " ... " + name + Primes(order - 1) : "") +
                             " (its equation is of order " + std::to_string(order) + ")",
                         Where(kv.first), key);
      if (!seen.insert(key).second)
        throw ModelError("initial_state '" + key + "' given twice", Where(kv.first), key);
      const std::string context = "in initial_state '" + key + "'";
      SourceText text;
      ex e = ParseScalar(kv.second, context, false, ConstantResolver(context), &text);
      model_.initial_state.emplace_back(key, text);
      symbolic_->initial_state.push_back({{v, primes}, e});
    }
  }

  // Without a guess, a variable of an autonomous oscillation (one unknown
  // base) of order >= 2 starts as the harmonic through its initial state,
  // x0 cos(w t) + v0/w sin(w t): the bundled examples' hand-written guess,
  // and the start a zero guess is not (the pendulum's lands on w/3). A
  // guess given in the file replaces it.
  void DefaultGuesses() {
    if (model_.frequencies.size() != 1 || !model_.frequencies[0].unknown) return;
    const ex w = symbolic_->bases[0];
    for (const auto& [vj, value] : symbolic_->initial_state) {
      const auto [v, primes] = vj;
      if (model_.orders[v] < 2 || primes > 1) continue;
      symbolic_->guess[v] += primes == 0 ? value * GiNaC::cos(w * symbolic_->t) : value / w * GiNaC::sin(w * symbolic_->t);
    }
  }

  void LoadGuess(const YAML::Node& node) {
    const std::size_t n = model_.variables.size();
    symbolic_->guess.assign(n, ex(0));
    symbolic_->has_guess.assign(n, false);
    DefaultGuesses();
    if (!node || node.IsNull()) return;
    if (!node.IsMap())
      throw ModelError("'guess' must be a map variable: expression of t", Where(node));
    for (const auto& kv : node) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : "";
      const int v = model_.IndexOfVariable(key);
      if (v < 0) throw ModelError("unknown variable '" + key + "' in guess", Where(kv.first), key);
      if (symbolic_->has_guess[v])
        throw ModelError("guess of '" + key + "' given twice", Where(kv.first), key);
      const std::string context = "in the guess of " + key;
      internal::Resolver resolver;
      resolver.symbol = [&](const std::string& name, int primes, std::size_t offset) -> ex {
        if (name == "t" && primes == 0) return symbolic_->t;
        ex out;
        if (ResolveCommon(name, primes, offset, &out, true)) return out;
        if (model_.IndexOfVariable(name) >= 0)
          throw ParseError{offset, "a guess is a function of t: variables are not allowed", name};
        throw ParseError{offset, UnknownSymbolMessage(name, context), name};
      };
      SourceText text;
      ex e = ParseScalar(kv.second, context, false, resolver, &text);
      model_.guess.emplace_back(key, text);
      symbolic_->guess[v] = e;
      symbolic_->has_guess[v] = true;
    }
  }

  const std::string& text_;
  const std::vector<std::string>& added_conditions_;
  const std::string frequency_guess_;
  ModelDefinition model_;
  std::shared_ptr<SymbolicModel> symbolic_;
  std::vector<SourceLocation> variable_where_;
};

}  // namespace

int ModelDefinition::IndexOfVariable(const std::string& n) const {
  for (std::size_t i = 0; i < variables.size(); ++i)
    if (variables[i] == n) return static_cast<int>(i);
  return -1;
}

const ParameterDefinition* ModelDefinition::FindParameter(const std::string& n) const {
  for (const auto& p : parameters)
    if (p.name == n) return &p;
  return nullptr;
}

ParameterValues ModelDefinition::ParameterValuesWith(const ParameterValues& overrides) const {
  ParameterValues values;
  for (const auto& p : parameters) values[p.name] = p.value;
  for (const auto& [name, value] : overrides) {
    if (!values.count(name)) {
      std::vector<std::string> names;
      for (const auto& p : parameters) names.push_back(p.name);
      throw ModelError("unknown parameter '" + name + "' in the overrides (" +
                           (names.empty() ? std::string("the model has no parameters")
                                          : "parameters: " + Join(names)) +
                           ")",
                       {source, 0, 0}, name);
    }
    if (!std::isfinite(value))
      throw ModelError("parameter '" + name + "' set to a non-finite value", {source, 0, 0}, name);
    values[name] = value;
  }
  return values;
}

ModelDefinition ParseModel(const std::string& text, const std::string& source_name,
                           const std::vector<std::string>& added_conditions, const std::string& frequency_guess) {
  try {
    Loader loader(text, source_name, added_conditions, frequency_guess);
    return loader.Load();
  } catch (const ModelError&) {
    throw;
  } catch (const YAML::Exception& e) {
    SourceLocation at{source_name, 0, 0};
    if (e.mark.line >= 0) at = {source_name, e.mark.line + 1, e.mark.column + 1};
    throw ModelError("YAML error: " + e.msg, at);
  } catch (const std::exception& e) {
    throw ModelError(std::string("cannot load the model: ") + e.what(), {source_name, 0, 0});
  }
}

ModelDefinition LoadModelFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ModelError("cannot open the model file", {path, 0, 0});
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  if (text.size() > (1u << 20)) throw ModelError("model file larger than 1 MiB", {path, 0, 0});
  return ParseModel(text, path);
}

}  // namespace rmhb::model
