#include "rmhb/model/internal/expression_parser.h"
#include "rmhb/model/internal/compile.h"

#include <charconv>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <set>

namespace rmhb::model::internal {
namespace {

using GiNaC::ex;
using GiNaC::numeric;

const std::set<std::string>& BuiltinFunctions() {
  static const std::set<std::string> names = {
      "sin",  "cos",  "tan",  "exp",    "log",    "ln",     "log10",  "log2",
      "sqrt", "cbrt", "asin", "acos",   "atan",   "arcsin", "arccos", "arctan",
      "sinh", "cosh", "tanh", "pow"};
  return names;
}

const std::set<std::string>& NonSmoothFunctions() {
  static const std::set<std::string> names = {
      "abs",  "fabs", "sign", "sgn",  "floor", "ceil",      "round",     "trunc", "frac",
      "min",  "max",  "mod",  "fmod", "step",  "heaviside", "Heaviside", "atan2",
      "csgn", "rem"};
  return names;
}

enum class TokenKind { kNumber, kIdentifier, kOperator, kEnd };

struct Token {
  TokenKind kind = TokenKind::kEnd;
  std::string text;  // operator text, identifier name or number literal
  int primes = 0;    // identifiers only
  std::size_t offset = 0;
};

class Parser {
 public:
  Parser(const std::string& text, const Resolver& resolver, const ParseLimits& limits)
      : text_(text), resolver_(resolver), limits_(limits) {
    if (text.size() > limits.max_length)
      throw ParseError{0,
                       "expression too long (" + std::to_string(text.size()) + " characters, at most " +
                           std::to_string(limits.max_length) + ")",
                       ""};
    Next();
  }

  ex ParseTop(bool equation) {
    if (current_.kind == TokenKind::kEnd) throw ParseError{current_.offset, "empty expression", ""};
    ex lhs = Expression();
    if (equation && IsOperator("=")) {
      const std::size_t at = current_.offset;
      Next();
      if (current_.kind == TokenKind::kEnd)
        throw ParseError{current_.offset, "missing right-hand side after '='", ""};
      ex rhs = Expression();
      if (IsOperator("="))
        throw ParseError{current_.offset, "more than one '=' in an equation", ""};
      lhs = Guard([&] { return lhs - rhs; }, at);
    }
    if (current_.kind != TokenKind::kEnd) {
      if (current_.kind == TokenKind::kOperator && current_.text == "=")
        throw ParseError{current_.offset, "'=' is not allowed here", ""};
      if (current_.kind == TokenKind::kOperator && current_.text == ")")
        throw ParseError{current_.offset, "unbalanced ')'", ""};
      throw ParseError{current_.offset,
                       "expected an operator before '" + current_.text + "'" +
                           (current_.kind == TokenKind::kOperator ? "" : " (write products with *)"),
                       ""};
    }
    return lhs;
  }

 private:
  template <class F>
  ex Guard(F f, std::size_t offset) {
    ex r;
    try {
      r = f();
    } catch (const ParseError&) {
      throw;
    } catch (const std::exception& e) {
      std::string what = e.what();
      if (what.find("division by zero") != std::string::npos) what = "division by zero";
      throw ParseError{offset, "cannot evaluate: " + what, ""};
    }
    CheckRange(r, offset);
    return r;
  }

  static void CheckRange(const ex& e, std::size_t offset) {
    if (!GiNaC::is_a<numeric>(e)) return;
    const numeric& n = GiNaC::ex_to<numeric>(e);
    if (!n.is_real()) throw ParseError{offset, "complex value " + Str(e), ""};
    if (n.is_zero()) return;
    // Large exact numbers would make later exact arithmetic slow (and do not
    // fit a double anyway); tiny ones are harmless.
    static const numeric big = numeric(10).power(308);
    if (GiNaC::abs(n) > big) throw ParseError{offset, "number out of range (beyond 1e308)", ""};
  }

  bool IsOperator(const char* op) const {
    return current_.kind == TokenKind::kOperator && current_.text == op;
  }

  void Enter(std::size_t offset) {
    if (++depth_ > limits_.max_depth)
      throw ParseError{offset, "expression nested too deeply", ""};
  }
  void Leave() { --depth_; }

  ex Expression() {
    Enter(current_.offset);
    ex result = Term();
    while (IsOperator("+") || IsOperator("-")) {
      const bool minus = current_.text == "-";
      const std::size_t at = current_.offset;
      Next();
      ex rhs = Term();
      result = Guard([&] { return minus ? result - rhs : result + rhs; }, at);
    }
    Leave();
    return result;
  }

  ex Term() {
    ex result = Unary();
    while (IsOperator("*") || IsOperator("/")) {
      const bool divide = current_.text == "/";
      const std::size_t at = current_.offset;
      Next();
      ex rhs = Unary();
      result = Guard([&] { return divide ? result / rhs : result * rhs; }, at);
    }
    return result;
  }

  ex Unary() {
    if (IsOperator("-") || IsOperator("+")) {
      const bool minus = current_.text == "-";
      const std::size_t at = current_.offset;
      Enter(at);
      Next();
      ex operand = Unary();
      Leave();
      return minus ? Guard([&] { return -operand; }, at) : operand;
    }
    return Power();
  }

  ex Power() {
    ex base = Primary();
    if (IsOperator("^") || IsOperator("**")) {
      const std::size_t at = current_.offset;
      Enter(at);
      Next();
      ex exponent = Unary();  // right associative, allows 2^-1
      Leave();
      return MakePower(base, exponent, at);
    }
    return base;
  }

  ex MakePower(const ex& base, const ex& exponent, std::size_t at) {
    if (GiNaC::is_a<numeric>(exponent)) {
      const numeric& n = GiNaC::ex_to<numeric>(exponent);
      if (!n.is_real()) throw ParseError{at, "complex exponent", ""};
      if (GiNaC::abs(n) > limits_.max_exponent)
        throw ParseError{at,
                         "exponent " + Str(exponent) + " too large (at most " +
                             std::to_string(limits_.max_exponent) + " in magnitude)",
                         ""};
      if (base.is_zero() && n.is_negative()) throw ParseError{at, "division by zero", ""};
    }
    return Guard([&] { return GiNaC::pow(base, exponent); }, at);
  }

  std::vector<ex> Arguments(const std::string& name) {
    // current_ is '('
    const std::size_t open = current_.offset;
    Enter(open);
    Next();
    std::vector<ex> args;
    if (IsOperator(")")) throw ParseError{current_.offset, name + "() needs an argument", name};
    while (true) {
      args.push_back(Expression());
      if (IsOperator(",")) {
        Next();
        continue;
      }
      if (IsOperator(")")) break;
      if (current_.kind == TokenKind::kEnd || IsOperator("="))
        throw ParseError{open, "missing ')' for the '(' here", ""};
      throw ParseError{current_.offset, "expected ',' or ')' in the arguments of " + name, ""};
    }
    Next();
    Leave();
    return args;
  }

  ex Primary() {
    const Token token = current_;
    switch (token.kind) {
      case TokenKind::kNumber: {
        numeric value;
        std::string why;
        if (!DecimalToRational(token.text, &value, &why)) throw ParseError{token.offset, why, ""};
        Next();
        return value;
      }
      case TokenKind::kIdentifier: {
        Next();
        if (IsOperator("(")) {
          if (token.primes == 0 && BuiltinFunctions().count(token.text))
            return Function(token, Arguments(token.text));
          if (token.primes == 0 && NonSmoothFunctions().count(token.text))
            throw ParseError{token.offset,
                             "function '" + token.text +
                                 "' is not supported: it is not smooth, and the recast into a "
                                 "polynomial system needs differentiable functions",
                             token.text};
          std::vector<ex> args = Arguments(token.text);
          if (!resolver_.call) {
            if (token.primes == 0 && !IsKnownName(token))
              throw ParseError{token.offset, "unknown function '" + token.text + "'", token.text};
            throw ParseError{token.offset,
                             "'" + token.text + std::string(token.primes, '\'') +
                                 "' is not a function (write products with *)",
                             token.text};
          }
          return Guard([&] { return resolver_.call(token.text, token.primes, args, token.offset); },
                       token.offset);
        }
        if (token.primes == 0 && BuiltinFunctions().count(token.text))
          throw ParseError{token.offset, "function '" + token.text + "' needs an argument: " +
                                             token.text + "(...)",
                           token.text};
        if (token.primes == 0 && NonSmoothFunctions().count(token.text))
          throw ParseError{token.offset,
                           "function '" + token.text + "' is not supported: it is not smooth",
                           token.text};
        if (token.primes > limits_.max_primes)
          throw ParseError{token.offset, "too many primes (derivative order above " +
                                             std::to_string(limits_.max_primes) + ")",
                           token.text};
        return Guard([&] { return resolver_.symbol(token.text, token.primes, token.offset); },
                     token.offset);
      }
      case TokenKind::kOperator:
        if (token.text == "(") {
          Enter(token.offset);
          Next();
          if (IsOperator(")")) throw ParseError{current_.offset, "empty parentheses", ""};
          ex inner = Expression();
          if (!IsOperator(")")) {
            if (current_.kind == TokenKind::kEnd)
              throw ParseError{token.offset, "missing ')' for the '(' here", ""};
            throw ParseError{current_.offset, "expected ')' before '" + current_.text + "'", ""};
          }
          Next();
          Leave();
          return inner;
        }
        throw ParseError{token.offset, "unexpected '" + token.text + "'", ""};
      case TokenKind::kEnd:
        throw ParseError{token.offset, "unexpected end of expression", ""};
    }
    throw ParseError{token.offset, "unexpected token", ""};
  }

  bool IsKnownName(const Token& token) {
    // Whether the resolver knows the name (then "name(" is a missing '*').
    try {
      resolver_.symbol(token.text, token.primes, token.offset);
      return true;
    } catch (...) {
      return false;
    }
  }

  ex Function(const Token& f, const std::vector<ex>& args) {
    const std::string& name = f.text;
    const std::size_t at = f.offset;
    auto arity = [&](std::size_t lo, std::size_t hi) {
      if (args.size() < lo || args.size() > hi)
        throw ParseError{at,
                         name + "() takes " +
                             (lo == hi ? std::to_string(lo)
                                       : std::to_string(lo) + " or " + std::to_string(hi)) +
                             " argument" + (hi > 1 ? "s" : "") + ", got " +
                             std::to_string(args.size()),
                         name};
    };
    if (name == "log") {
      arity(1, 2);
      if (args.size() == 2)
        return Guard([&] { return GiNaC::log(args[0]) / GiNaC::log(args[1]); }, at);
      return Guard([&] { return GiNaC::log(args[0]); }, at);
    }
    if (name == "pow") {
      arity(2, 2);
      return MakePower(args[0], args[1], at);
    }
    arity(1, 1);
    const ex& x = args[0];
    if (name == "sin") return Guard([&] { return GiNaC::sin(x); }, at);
    if (name == "cos") return Guard([&] { return GiNaC::cos(x); }, at);
    if (name == "tan") return Guard([&] { return GiNaC::tan(x); }, at);
    if (name == "exp") return Guard([&] { return GiNaC::exp(x); }, at);
    if (name == "ln") return Guard([&] { return GiNaC::log(x); }, at);
    if (name == "log10") return Guard([&] { return GiNaC::log(x) / GiNaC::log(ex(10)); }, at);
    if (name == "log2") return Guard([&] { return GiNaC::log(x) / GiNaC::log(ex(2)); }, at);
    if (name == "sqrt") return MakePower(x, numeric(1, 2), at);
    if (name == "cbrt") return MakePower(x, numeric(1, 3), at);
    if (name == "asin" || name == "arcsin") return Guard([&] { return GiNaC::asin(x); }, at);
    if (name == "acos" || name == "arccos") return Guard([&] { return GiNaC::acos(x); }, at);
    if (name == "atan" || name == "arctan") return Guard([&] { return GiNaC::atan(x); }, at);
    if (name == "sinh") return Guard([&] { return GiNaC::sinh(x); }, at);
    if (name == "cosh") return Guard([&] { return GiNaC::cosh(x); }, at);
    if (name == "tanh") return Guard([&] { return GiNaC::tanh(x); }, at);
    throw ParseError{at, "unknown function '" + name + "'", name};
  }

  void Next() {
    std::size_t i = position_;
    while (i < text_.size() && std::isspace(static_cast<unsigned char>(text_[i]))) ++i;
    current_ = Token{};
    current_.offset = i;
    if (i >= text_.size()) {
      current_.kind = TokenKind::kEnd;
      position_ = i;
      return;
    }
    const char c = text_[i];
    auto digit = [&](std::size_t k) {
      return k < text_.size() && std::isdigit(static_cast<unsigned char>(text_[k]));
    };
    if (digit(i) || (c == '.' && digit(i + 1))) {
      std::size_t j = i;
      while (digit(j)) ++j;
      if (j < text_.size() && text_[j] == '.') {
        ++j;
        while (digit(j)) ++j;
      }
      if (j < text_.size() && (text_[j] == 'e' || text_[j] == 'E')) {
        std::size_t k = j + 1;
        if (k < text_.size() && (text_[k] == '+' || text_[k] == '-')) ++k;
        if (digit(k)) {
          while (digit(k)) ++k;
          j = k;
        }
      }
      current_.kind = TokenKind::kNumber;
      current_.text = text_.substr(i, j - i);
      position_ = j;
      if (j < text_.size() &&
          (std::isalpha(static_cast<unsigned char>(text_[j])) || text_[j] == '_'))
        throw ParseError{j, "expected an operator after the number '" + current_.text +
                                "' (write products with *)",
                         ""};
      return;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      std::size_t j = i;
      while (j < text_.size() &&
             (std::isalnum(static_cast<unsigned char>(text_[j])) || text_[j] == '_'))
        ++j;
      current_.kind = TokenKind::kIdentifier;
      current_.text = text_.substr(i, j - i);
      while (j < text_.size() && text_[j] == '\'') {
        ++current_.primes;
        ++j;
      }
      position_ = j;
      return;
    }
    current_.kind = TokenKind::kOperator;
    if (c == '*' && i + 1 < text_.size() && text_[i + 1] == '*') {
      current_.text = "**";
      position_ = i + 2;
      return;
    }
    if (c == '=' && i + 1 < text_.size() && text_[i + 1] == '=')
      throw ParseError{i, "use a single '=' in equations", ""};
    static const std::string single = "+-*/^(),=";
    if (single.find(c) == std::string::npos) {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", static_cast<unsigned char>(c));
      const std::string shown = std::isprint(static_cast<unsigned char>(c)) ? std::string(1, c) : hex;
      if (c == '\'') throw ParseError{i, "a prime must follow a variable name", ""};
      throw ParseError{i, "unexpected character '" + shown + "'", ""};
    }
    current_.text = std::string(1, c);
    position_ = i + 1;
  }

  const std::string& text_;
  const Resolver& resolver_;
  const ParseLimits& limits_;
  std::size_t position_ = 0;
  int depth_ = 0;
  Token current_;
};

}  // namespace

GiNaC::ex ParseExpression(const std::string& text, const Resolver& resolver,
                          const ParseLimits& limits) {
  Parser parser(text, resolver, limits);
  return parser.ParseTop(false);
}

GiNaC::ex ParseEquation(const std::string& text, const Resolver& resolver,
                        const ParseLimits& limits) {
  Parser parser(text, resolver, limits);
  return parser.ParseTop(true);
}

bool IsBuiltinFunctionName(const std::string& name) { return BuiltinFunctions().count(name) > 0; }
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

bool DecimalToRational(const std::string& text, GiNaC::numeric* value, std::string* why) {
  std::size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '+' || text[i] == '-')) negative = text[i++] == '-';
  std::string digits;
  int fraction_digits = 0;
  bool any = false, dot = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (std::isdigit(static_cast<unsigned char>(c))) {
      any = true;
      if (digits.empty() && c == '0') {
        if (dot) ++fraction_digits;
        continue;  // leading zeros
      }
      digits += c;
      if (dot) ++fraction_digits;
    } else if (c == '.' && !dot) {
      dot = true;
    } else {
      break;
    }
  }
  if (!any) {
    *why = "'" + text + "' is not a number";
    return false;
  }
  long exponent = 0;
  if (i < text.size() && (text[i] == 'e' || text[i] == 'E')) {
    ++i;
    bool eneg = false;
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) eneg = text[i++] == '-';
    if (i >= text.size()) {
      *why = "'" + text + "' is not a number";
      return false;
    }
    for (; i < text.size() && std::isdigit(static_cast<unsigned char>(text[i])); ++i) {
      exponent = exponent * 10 + (text[i] - '0');
      if (exponent > 100000) break;
    }
    if (eneg) exponent = -exponent;
  }
  if (i != text.size()) {
    *why = "'" + text + "' is not a number";
    return false;
  }
  // Drop trailing zeros of the digit string into the exponent.
  while (digits.size() > 1 && digits.back() == '0') {
    digits.pop_back();
    if (fraction_digits > 0) --fraction_digits;
    else ++exponent;
  }
  if (digits.empty()) {
    *value = 0;
    return true;
  }
  if (digits.size() > 40) {
    *why = "number '" + text + "' has too many digits (at most 40)";
    return false;
  }
  const long scale = exponent - fraction_digits;
  const long magnitude = scale + static_cast<long>(digits.size());  // ~ log10 |value| + 1
  if (magnitude > 309 || magnitude < -330) {
    *why = "number '" + text + "' is out of range";
    return false;
  }
  numeric m(digits.c_str());
  m = m * numeric(10).power(numeric(scale));
  *value = negative ? -m : m;
  return true;
}

GiNaC::numeric RationalFromDouble(double value) {
  char buffer[64];
  auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  std::string text(buffer, result.ptr);
  numeric n;
  std::string why;
  if (!DecimalToRational(text, &n, &why)) {
    // Tiny or huge values beyond the literal range: exact binary value.
    int e = 0;
    const double m = std::frexp(value, &e);
    const long long mantissa = static_cast<long long>(std::ldexp(m, 53));
    return numeric(static_cast<long>(mantissa)) * numeric(2).power(numeric(e - 53));
  }
  return n;
}

}  // namespace rmhb::model::internal
