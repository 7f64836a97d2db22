#include "rmhb/model/internal/expression_parser.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>

#include "rmhb/model/internal/compile.h"
#include "rmhb/model/internal/exact_numbers.h"
#include "rmhb/model/internal/nonsmooth.h"

namespace rmhb::model::internal {
namespace {

using GiNaC::ex;
using GiNaC::exvector;
using GiNaC::numeric;

constexpr std::size_t kNone = static_cast<std::size_t>(-1);

// ---- functions -------------------------------------------------------------------------------
// The functions a model may call, as GiNaC parser prototypes. The recast
// supports exactly the GiNaC functions these produce (see kRecastFunctions).
struct FunctionEntry {
  const char* name;
  std::size_t arity;
  GiNaC::reader_func read;
};

// GiNaC's parser reads a prototype whose address is odd as the serial number
// of a GiNaC function (its parser.cpp "KLUDGE"), so the readers are aligned
// explicitly: without optimisation GCC does not align functions.
[[gnu::aligned(16)]] ex ReadSin(const exvector& a) { return GiNaC::sin(a[0]); }
[[gnu::aligned(16)]] ex ReadCos(const exvector& a) { return GiNaC::cos(a[0]); }
[[gnu::aligned(16)]] ex ReadTan(const exvector& a) { return GiNaC::tan(a[0]); }
[[gnu::aligned(16)]] ex ReadExp(const exvector& a) { return GiNaC::exp(a[0]); }
[[gnu::aligned(16)]] ex ReadLog(const exvector& a) { return GiNaC::log(a[0]); }
[[gnu::aligned(16)]] ex ReadLogBase(const exvector& a) { return GiNaC::log(a[0]) / GiNaC::log(a[1]); }
[[gnu::aligned(16)]] ex ReadLog10(const exvector& a) { return GiNaC::log(a[0]) / GiNaC::log(ex(10)); }
[[gnu::aligned(16)]] ex ReadLog2(const exvector& a) { return GiNaC::log(a[0]) / GiNaC::log(ex(2)); }
[[gnu::aligned(16)]] ex ReadSqrt(const exvector& a) { return GiNaC::pow(a[0], numeric(1, 2)); }
[[gnu::aligned(16)]] ex ReadCbrt(const exvector& a) { return GiNaC::pow(a[0], numeric(1, 3)); }
[[gnu::aligned(16)]] ex ReadPow(const exvector& a) { return GiNaC::pow(a[0], a[1]); }
[[gnu::aligned(16)]] ex ReadAsin(const exvector& a) { return GiNaC::asin(a[0]); }
[[gnu::aligned(16)]] ex ReadAcos(const exvector& a) { return GiNaC::acos(a[0]); }
[[gnu::aligned(16)]] ex ReadAtan(const exvector& a) { return GiNaC::atan(a[0]); }
[[gnu::aligned(16)]] ex ReadSinh(const exvector& a) { return GiNaC::sinh(a[0]); }
[[gnu::aligned(16)]] ex ReadCosh(const exvector& a) { return GiNaC::cosh(a[0]); }
[[gnu::aligned(16)]] ex ReadTanh(const exvector& a) { return GiNaC::tanh(a[0]); }
// Piecewise-smooth functions (METHOD.md s.15), in three primitives.
[[gnu::aligned(16)]] ex ReadAbs(const exvector& a) { return Abs(a[0]); }
[[gnu::aligned(16)]] ex ReadMax(const exvector& a) { return Max(a[0], a[1]); }
[[gnu::aligned(16)]] ex ReadMin(const exvector& a) { return Min(a[0], a[1]); }
[[gnu::aligned(16)]] ex ReadSign(const exvector& a) { return sgn(a[0]); }
[[gnu::aligned(16)]] ex ReadHeaviside(const exvector& a) { return heaviside(a[0]); }
[[gnu::aligned(16)]] ex ReadClamp(const exvector& a) { return Clamp(a[0], a[1], a[2]); }
[[gnu::aligned(16)]] ex ReadCoulomb(const exvector& a) { return coulomb(a[0], a[1], 0); }
[[gnu::aligned(16)]] ex ReadCoulombEps(const exvector& a) { return coulomb(a[0], a[1], a[2]); }

const std::vector<FunctionEntry>& Functions() {
  static const std::vector<FunctionEntry> table = {
      {"sin", 1, ReadSin},
      {"cos", 1, ReadCos},
      {"tan", 1, ReadTan},
      {"exp", 1, ReadExp},
      {"log", 1, ReadLog},
      {"log", 2, ReadLogBase},
      {"ln", 1, ReadLog},
      {"log10", 1, ReadLog10},
      {"log2", 1, ReadLog2},
      {"sqrt", 1, ReadSqrt},
      {"cbrt", 1, ReadCbrt},
      {"pow", 2, ReadPow},
      {"asin", 1, ReadAsin},
      {"acos", 1, ReadAcos},
      {"atan", 1, ReadAtan},
      {"arcsin", 1, ReadAsin},
      {"arccos", 1, ReadAcos},
      {"arctan", 1, ReadAtan},
      {"sinh", 1, ReadSinh},
      {"cosh", 1, ReadCosh},
      {"tanh", 1, ReadTanh},
      {"abs", 1, ReadAbs},
      {"max", 2, ReadMax},
      {"min", 2, ReadMin},
      {"sign", 1, ReadSign},
      {"heaviside", 1, ReadHeaviside},
      {"clamp", 3, ReadClamp},
      {"coulomb", 2, ReadCoulomb},
      {"coulomb", 3, ReadCoulombEps}};
  return table;
}

// What the recast knows how to turn into polynomial equations.
const std::set<std::string> kRecastFunctions = {"sin",  "cos",  "tan",  "exp",  "log", "asin",
                                                "acos", "atan", "sinh", "cosh", "tanh",
                                                // piecewise smooth: pointwise, not recast
                                                "ramp", "heaviside", "sgn", "coulomb"};

// Functions a model may not call: discontinuous beyond a single switch, or
// spelt in another way here.
const char* const kNonSmoothHint =
    ": piecewise-smooth terms are written with abs, max, min, sign, heaviside, clamp or "
    "coulomb (Coulomb friction)";

const std::set<std::string>& NonSmoothFunctions() {
  static const std::set<std::string> names = {
      "fabs", "sgn",  "floor", "ceil", "round", "trunc", "frac", "mod",
      "fmod", "step", "Heaviside", "atan2", "csgn", "rem", "ramp"};
  return names;
}

const GiNaC::prototype_table& Prototypes() {
  static const GiNaC::prototype_table table = [] {
    GiNaC::prototype_table t;
    for (const FunctionEntry& f : Functions()) {
      if (reinterpret_cast<std::uintptr_t>(f.read) & 1)
        throw std::logic_error("GiNaC parser reader at an odd address");
      t[{f.name, f.arity}] = f.read;
    }
    return t;
  }();
  return table;
}

// Smallest and largest argument counts of a built-in function (0, 0 if none).
std::pair<std::size_t, std::size_t> Arity(const std::string& name) {
  std::size_t lo = 0, hi = 0;
  for (const FunctionEntry& f : Functions())
    if (name == f.name) {
      lo = lo ? std::min(lo, f.arity) : f.arity;
      hi = std::max(hi, f.arity);
    }
  return {lo, hi};
}

// ---- pre-tokenizer ---------------------------------------------------------------------------
enum class TokenKind { kNumber, kName, kOperator, kEnd };

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string text;  // operator ("**" is "^"), name or number literal
  int primes = 0;    // names only
  std::size_t offset = 0;
};

std::vector<Token> Tokenize(const std::string& text, const ParseLimits& limits) {
  if (text.size() > limits.max_length)
    throw ParseError{0,
                     "expression too long (" + std::to_string(text.size()) + " characters, at most " +
                         std::to_string(limits.max_length) + ")",
                     ""};
  std::vector<Token> tokens;
  auto digit = [&](std::size_t k) {
    return k < text.size() && std::isdigit(static_cast<unsigned char>(text[k]));
  };
  std::size_t i = 0;
  while (true) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    Token token;
    token.offset = i;
    if (i >= text.size()) {
      tokens.push_back(token);
      return tokens;
    }
    const char c = text[i];
    if (digit(i) || (c == '.' && digit(i + 1))) {
      std::size_t j = i;
      while (digit(j)) ++j;
      if (j < text.size() && text[j] == '.') {
        ++j;
        while (digit(j)) ++j;
      }
      if (j < text.size() && (text[j] == 'e' || text[j] == 'E')) {
        std::size_t k = j + 1;
        if (k < text.size() && (text[k] == '+' || text[k] == '-')) ++k;
        if (digit(k)) {
          while (digit(k)) ++k;
          j = k;
        }
      }
      token.kind = TokenKind::kNumber;
      token.text = text.substr(i, j - i);
      if (j < text.size() && (std::isalpha(static_cast<unsigned char>(text[j])) || text[j] == '_'))
        throw ParseError{j, "expected an operator after the number '" + token.text +
                                "' (write products with *)",
                         ""};
      i = j;
    } else if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t j = i;
      while (j < text.size() && (std::isalnum(static_cast<unsigned char>(text[j])) || text[j] == '_'))
        ++j;
      token.kind = TokenKind::kName;
      token.text = text.substr(i, j - i);
      while (j < text.size() && text[j] == '\'') {
        ++token.primes;
        ++j;
      }
      i = j;
    } else {
      token.kind = TokenKind::kOperator;
      if (c == '*' && i + 1 < text.size() && text[i + 1] == '*') {
        token.text = "^";
        i += 2;
      } else {
        if (c == '=' && i + 1 < text.size() && text[i + 1] == '=')
          throw ParseError{i, "use a single '=' in equations", ""};
        static const std::string single = "+-*/^(),=";
        if (single.find(c) == std::string::npos) {
          if (c == '\'') throw ParseError{i, "a prime must follow a variable name", ""};
          char hex[8];
          std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
          const std::string shown =
              std::isprint(static_cast<unsigned char>(c)) ? std::string(1, c) : hex;
          throw ParseError{i, "unexpected character '" + shown + "'", ""};
        }
        token.text = std::string(1, c);
        ++i;
      }
    }
    tokens.push_back(token);
  }
}

// ---- check, rewrite for GiNaC, parse, substitute ---------------------------------------------
class Translator {
 public:
  Translator(const std::vector<Token>& tokens, const Resolver& resolver, const ParseLimits& limits,
             int depth)
      : tokens_(tokens), resolver_(resolver), limits_(limits), depth_(depth) {
    match_.assign(tokens.size(), kNone);
    std::vector<std::size_t> open;
    for (std::size_t i = 0; i < tokens.size(); ++i) {
      if (IsOperator(i, "(")) open.push_back(i);
      if (IsOperator(i, ")") && !open.empty()) {
        match_[open.back()] = i;
        match_[i] = open.back();
        open.pop_back();
      }
    }
  }

  // Tokens [begin, end): an expression, or "lhs = rhs" giving lhs - rhs.
  ex Parse(std::size_t begin, std::size_t end, bool equation) {
    begin_ = begin;
    end_ = end;
    Check(equation);
    return Substitute(RunGinac(Rewrite()));
  }

 private:
  bool IsOperator(std::size_t i, const char* op) const {
    return i < tokens_.size() && tokens_[i].kind == TokenKind::kOperator && tokens_[i].text == op;
  }
  bool IsBinary(std::size_t i) const {
    return IsOperator(i, "+") || IsOperator(i, "-") || IsOperator(i, "*") || IsOperator(i, "/") ||
           IsOperator(i, "^");
  }
  // name followed by '(' (a function, or x(0) in a condition).
  bool IsCall(std::size_t i) const {
    return tokens_[i].kind == TokenKind::kName && i + 1 < end_ && IsOperator(i + 1, "(");
  }
  bool IsBuiltinCall(std::size_t i) const {
    return IsCall(i) && tokens_[i].primes == 0 && Arity(tokens_[i].text).first > 0;
  }
  [[noreturn]] void Fail(std::size_t i, const std::string& message,
                         const std::string& symbol = "") const {
    throw ParseError{tokens_[i].offset, message, symbol};
  }
  std::string Shown(std::size_t i) const {
    return tokens_[i].text + std::string(static_cast<std::size_t>(tokens_[i].primes), '\'');
  }

  // Step 1: the token sequence, left to right, so the first error is the
  // leftmost; names are resolved here, with their offsets.
  void Check(bool equation) {
    struct Frame {
      std::size_t open;
      std::size_t function;  // kNone for a parenthesised group
      std::size_t commas;
    };
    std::vector<Frame> frames;
    if (begin_ == end_) Fail(begin_, "empty expression");
    bool want_operand = true;
    for (std::size_t i = begin_; i < end_; ++i) {
      const Token& token = tokens_[i];
      if (want_operand) {
        if (token.kind == TokenKind::kNumber) {
          AddNumber(i);
          want_operand = false;
        } else if (token.kind == TokenKind::kName) {
          if (IsBuiltinCall(i)) {
            if (IsOperator(i + 2, ")")) Fail(i, token.text + "() needs an argument", token.text);
            frames.push_back({i + 1, i, 0});
            CheckDepth(frames.size(), i + 1);
            ++i;
          } else if (IsCall(i)) {
            i = AddCall(i);
            want_operand = false;
          } else {
            AddName(i);
            want_operand = false;
          }
        } else if (IsOperator(i, "(")) {
          if (IsOperator(i + 1, ")")) Fail(i + 1, "empty parentheses");
          frames.push_back({i, kNone, 0});
          CheckDepth(frames.size(), i);
        } else if (!IsOperator(i, "+") && !IsOperator(i, "-")) {
          Fail(i, "unexpected '" + token.text + "'");
        }
        continue;
      }
      if (token.kind != TokenKind::kOperator)
        Fail(i, "expected an operator before '" + Shown(i) + "' (write products with *)");
      if (IsBinary(i)) {
        want_operand = true;
      } else if (token.text == ")") {
        if (frames.empty()) Fail(i, "unbalanced ')'");
        const Frame frame = frames.back();
        frames.pop_back();
        if (frame.function != kNone) {
          const std::string& name = tokens_[frame.function].text;
          const auto [lo, hi] = Arity(name);
          const std::size_t n = frame.commas + 1;
          if (n < lo || n > hi)
            Fail(frame.function,
                 name + "() takes " +
                     (lo == hi ? std::to_string(lo) : std::to_string(lo) + " or " + std::to_string(hi)) +
                     " argument" + (hi > 1 ? "s" : "") + ", got " + std::to_string(n),
                 name);
        }
      } else if (token.text == ",") {
        if (frames.empty() || frames.back().function == kNone)
          Fail(i, frames.empty() ? "unexpected ','" : "expected ')' before ','");
        ++frames.back().commas;
        want_operand = true;
      } else if (token.text == "=") {
        if (!frames.empty()) Fail(frames.back().open, "missing ')' for the '(' here");
        if (!equation) Fail(i, "'=' is not allowed here");
        if (split_ != kNone) Fail(i, "more than one '=' in an equation");
        if (i + 1 == end_) Fail(end_, "missing right-hand side after '='");
        split_ = i;
        want_operand = true;
      } else {
        Fail(i, "expected an operator before '" + token.text + "'");
      }
    }
    if (!frames.empty()) Fail(frames.back().open, "missing ')' for the '(' here");
    if (want_operand) Fail(end_, "unexpected end of expression");
  }

  void CheckDepth(std::size_t frames, std::size_t i) const {
    if (static_cast<int>(frames) + depth_ > limits_.max_depth)
      Fail(i, "expression nested too deeply");
  }

  void AddNumber(std::size_t i) {
    numeric value;
    std::string why;
    if (!DecimalToRational(tokens_[i].text, &value, &why)) Fail(i, why);
    const GiNaC::symbol placeholder("n" + std::to_string(i));
    numbers_.emplace(placeholder, Number{value, tokens_[i].offset});
    table_["n" + std::to_string(i)] = placeholder;
  }

  void AddName(std::size_t i) {
    const Token& token = tokens_[i];
    if (token.primes == 0 && Arity(token.text).first > 0)
      Fail(i, "function '" + token.text + "' needs an argument: " + token.text + "(...)", token.text);
    if (token.primes == 0 && NonSmoothFunctions().count(token.text))
      Fail(i, "function '" + token.text + "' is not supported" + kNonSmoothHint, token.text);
    if (token.primes > limits_.max_primes)
      Fail(i, "too many primes (derivative order above " + std::to_string(limits_.max_primes) + ")",
           token.text);
    table_["s" + std::to_string(i)] = resolver_.symbol(token.text, token.primes, token.offset);
  }

  // name(args) for a name that is not a built-in function: the caller's
  // `call` (x'(0) in conditions) gets the arguments, parsed on their own.
  // Returns the index of the closing parenthesis.
  std::size_t AddCall(std::size_t i) {
    const Token& token = tokens_[i];
    if (token.primes == 0 && NonSmoothFunctions().count(token.text))
      Fail(i,
           "function '" + token.text + "' is not supported" + kNonSmoothHint,
           token.text);
    if (!resolver_.call) {
      bool known = true;
      try {
        resolver_.symbol(token.text, token.primes, token.offset);
      } catch (const ParseError&) {
        known = false;
      }
      if (token.primes == 0 && !known) Fail(i, "unknown function '" + token.text + "'", token.text);
      Fail(i, "'" + Shown(i) + "' is not a function (write products with *)", token.text);
    }
    const std::size_t close = match_[i + 1];
    if (close == kNone || close >= end_) Fail(i + 1, "missing ')' for the '(' here");
    CheckDepth(1, i + 1);
    std::vector<ex> args;
    std::size_t start = i + 2, level = 0;
    for (std::size_t j = start; j <= close; ++j) {
      if (j == close || (IsOperator(j, ",") && level == 0)) {
        Translator inner(tokens_, resolver_, limits_, depth_ + 1);
        args.push_back(inner.Parse(start, j, false));
        start = j + 1;
      }
      if (IsOperator(j, "(")) ++level;
      if (IsOperator(j, ")")) --level;
    }
    table_["s" + std::to_string(i)] = resolver_.call(token.text, token.primes, args, token.offset);
    return close;
  }

  // One past the last token of the operand that starts at i: signs, then a
  // primary (number, name, call, group), then '^' and another such operand.
  std::size_t OperandEnd(std::size_t i) const {
    while (true) {
      while (IsOperator(i, "+") || IsOperator(i, "-")) ++i;
      if (IsCall(i)) i = match_[i + 1] + 1;
      else if (IsOperator(i, "(")) i = match_[i] + 1;
      else ++i;
      if (i < end_ && IsOperator(i, "^")) {
        ++i;
        continue;
      }
      return i;
    }
  }

  // Step 2: GiNaC-safe text. GiNaC reads a sign after an operator as the
  // start of a whole expression (2^-1+x would be 2^(-1+x)) and refuses
  // a^b^c, so those operands get explicit parentheses.
  std::string Rewrite() {
    const std::size_t n = end_ - begin_ + 1;
    std::vector<int> opens(n, 0), closes(n, 0);
    for (std::size_t i = begin_; i < end_; ++i) {
      if (IsCall(i) && !IsBuiltinCall(i)) {  // x'(0): one placeholder
        i = match_[i + 1];
        continue;
      }
      const bool power = IsOperator(i, "^");
      const bool sign_after_operator =
          (IsOperator(i, "+") || IsOperator(i, "-")) && i > begin_ && IsBinary(i - 1);
      if (!power && !sign_after_operator) continue;
      const std::size_t first = power ? i + 1 : i;
      ++opens[first - begin_];
      ++closes[OperandEnd(first) - begin_];
    }
    std::string out;
    int depth = depth_;
    auto emit = [&](const std::string& s, std::size_t i) {
      out += s;
      out += ' ';
      origin_.insert(origin_.end(), s.size() + 1, tokens_[i].offset);
    };
    for (std::size_t i = begin_; i <= end_; ++i) {
      for (int k = 0; k < closes[i - begin_]; ++k, --depth) emit(")", i);
      if (i == end_) break;
      for (int k = 0; k < opens[i - begin_]; ++k) {
        if (++depth > limits_.max_depth) Fail(i, "expression nested too deeply");
        emit("(", i);
      }
      const Token& token = tokens_[i];
      if (token.kind == TokenKind::kNumber) {
        emit("n" + std::to_string(i), i);
      } else if (IsBuiltinCall(i)) {
        emit(token.text, i);
      } else if (token.kind == TokenKind::kName) {
        emit("s" + std::to_string(i), i);
        if (IsCall(i)) i = match_[i + 1];
      } else if (i == split_) {
        emit("-(", i);
      } else {
        if (token.text == "(" && ++depth > limits_.max_depth) Fail(i, "expression nested too deeply");
        if (token.text == ")") --depth;
        emit(token.text, i);
      }
    }
    if (split_ != kNone) emit(")", end_);
    return out;
  }

  // Step 3: GiNaC's parser, strict: every name is in the symbol table.
  ex RunGinac(const std::string& text) const {
    GiNaC::parser reader(table_, /*strict=*/true, Prototypes());
    try {
      return reader(text);
    } catch (const GiNaC::parse_error& e) {
      // Not expected after Check; GiNaC 1.8 reports column 0, so the
      // emitted-text column is used only when it is given.
      const std::size_t at = e.column > 0 && e.column <= origin_.size() ? origin_[e.column - 1]
                                                                         : tokens_[begin_].offset;
      std::string what = e.what();
      what = what.substr(0, what.find('\n'));
      throw ParseError{at, "cannot parse: " + what, ""};
    } catch (const std::exception& e) {
      throw ParseError{tokens_[begin_].offset, "cannot evaluate: " + Reason(e), ""};
    }
  }

  static std::string Reason(const std::exception& e) {
    const std::string what = e.what();
    return what.find("division by zero") != std::string::npos ? "division by zero" : what;
  }

  // The numbers go in bottom-up, each node checked before GiNaC evaluates
  // the next one up (10^10^10 never reaches GiNaC's exact arithmetic).
  ex Substitute(const ex& e) const {
    using GiNaC::is_a;
    if (is_a<GiNaC::symbol>(e)) {
      auto it = numbers_.find(e);
      return it == numbers_.end() ? e : ex(it->second.value);
    }
    if (is_a<GiNaC::numeric>(e) || is_a<GiNaC::constant>(e)) return e;
    ex result;
    try {
      if (is_a<GiNaC::power>(e)) {
        const ex base = Substitute(e.op(0));
        const ex exponent = Substitute(e.op(1));
        CheckExponent(base, exponent, e);
        result = GiNaC::pow(base, exponent);
      } else if (is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e)) {
        const bool add = is_a<GiNaC::add>(e);
        result = add ? ex(0) : ex(1);
        for (std::size_t k = 0; k < e.nops(); ++k)
          result = add ? result + Substitute(e.op(k)) : result * Substitute(e.op(k));
      } else if (is_a<GiNaC::function>(e)) {
        const GiNaC::function& f = GiNaC::ex_to<GiNaC::function>(e);
        if (!kRecastFunctions.count(f.get_name()))
          throw ParseError{Where(e), "function '" + f.get_name() + "' is not supported", f.get_name()};
        exvector args;
        for (std::size_t k = 0; k < e.nops(); ++k) args.push_back(Substitute(e.op(k)));
        result = GiNaC::function(f.get_serial(), args);
      } else {
        throw ParseError{Where(e), "unsupported expression " + Str(e), ""};
      }
    } catch (const ParseError&) {
      throw;
    } catch (const std::exception& err) {
      throw ParseError{Where(e), "cannot evaluate: " + Reason(err), ""};
    }
    CheckRange(result, e);
    return result;
  }

  void CheckExponent(const ex& base, const ex& exponent, const ex& node) const {
    if (!GiNaC::is_a<numeric>(exponent)) return;
    const numeric& n = GiNaC::ex_to<numeric>(exponent);
    if (!n.is_real()) throw ParseError{Where(node), "complex exponent", ""};
    if (GiNaC::abs(n) > limits_.max_exponent)
      throw ParseError{Where(node.op(1)),
                       "exponent " + Str(exponent) + " too large (at most " +
                           std::to_string(limits_.max_exponent) + " in magnitude)",
                       ""};
    if (base.is_zero() && n.is_negative())
      throw ParseError{Where(node.op(0)), "cannot evaluate: division by zero", ""};
  }

  void CheckRange(const ex& value, const ex& node) const {
    if (!GiNaC::is_a<numeric>(value)) return;
    const numeric& n = GiNaC::ex_to<numeric>(value);
    if (!n.is_real()) throw ParseError{Where(node), "complex value " + Str(value), ""};
    if (n.is_zero()) return;
    // Large exact numbers would make later exact arithmetic slow (and do not
    // fit a double anyway); tiny ones are harmless.
    static const numeric big = numeric(10).power(308);
    if (GiNaC::abs(n) > big) throw ParseError{Where(node), "number out of range (beyond 1e308)", ""};
    // A small value may still be a huge fraction: ((2/3)^64)^64 has 2000
    // digits, and two more powers would not finish.
    static const numeric digits = numeric(2).power(4096);
    if (GiNaC::abs(n.numer()) > digits || n.denom() > digits)
      throw ParseError{Where(node), "number " + Str(value).substr(0, 20) + "... has too many digits", ""};
  }

  // Offset of the leftmost number in a (not yet substituted) node; the start
  // of the expression when it has none.
  std::size_t Where(const ex& node) const {
    std::size_t at = kNone;
    for (GiNaC::const_preorder_iterator it = node.preorder_begin(); it != node.preorder_end(); ++it) {
      auto number = numbers_.find(*it);
      if (number != numbers_.end()) at = std::min(at, number->second.offset);
    }
    return at == kNone ? tokens_[begin_].offset : at;
  }

  struct Number {
    numeric value;
    std::size_t offset;
  };

  const std::vector<Token>& tokens_;
  const Resolver& resolver_;
  const ParseLimits& limits_;
  const int depth_;
  std::vector<std::size_t> match_;  // index of the matching parenthesis
  std::size_t begin_ = 0, end_ = 0;
  std::size_t split_ = kNone;       // the '=' of an equation
  GiNaC::symtab table_;             // placeholder name -> expression
  std::map<ex, Number, GiNaC::ex_is_less> numbers_;  // placeholder symbol -> number
  std::vector<std::size_t> origin_;  // emitted character -> offset in the text
};

ex Parse(const std::string& text, const Resolver& resolver, const ParseLimits& limits,
         bool equation) {
  const std::vector<Token> tokens = Tokenize(text, limits);
  Translator translator(tokens, resolver, limits, 0);
  return translator.Parse(0, tokens.size() - 1, equation);
}

}  // namespace

GiNaC::ex ParseExpression(const std::string& text, const Resolver& resolver,
                          const ParseLimits& limits) {
  return Parse(text, resolver, limits, false);
}

GiNaC::ex ParseEquation(const std::string& text, const Resolver& resolver,
                        const ParseLimits& limits) {
  return Parse(text, resolver, limits, true);
}

bool IsBuiltinFunctionName(const std::string& name) { return Arity(name).first > 0; }
bool IsNonSmoothFunctionName(const std::string& name) {
  return NonSmoothFunctions().count(name) > 0;
}

bool IsValidIdentifier(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  if (!std::isalpha(static_cast<unsigned char>(name[0])) && name[0] != '_') return false;
  for (char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

}  // namespace rmhb::model::internal
