#ifndef RMHB_MODEL_INTERNAL_EXPRESSION_PARSER_H_
#define RMHB_MODEL_INTERNAL_EXPRESSION_PARSER_H_

// Natural-notation expressions -> GiNaC. A small recursive-descent parser
// rather than GiNaC's own: it knows primes (x'' is one token, handed to the
// caller's resolver as name "x" with 2 primes), reports errors with the
// character offset so the caller can point at the file line/column, refuses
// non-smooth functions with a reason, and bounds everything that could make
// GiNaC hang on hostile input (nesting depth, exponent size, literal size).
//
// Decimal literals become exact rationals (0.85 -> 17/20), so exponents like
// 3/2 or 1.5 are recognised as radicals by the recast.

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <ginac/ginac.h>

namespace rmhb::model::internal {

struct ParseError {
  std::size_t offset = 0;  // in the parsed text
  std::string message;
  std::string symbol;
};

struct ParseLimits {
  std::size_t max_length = 20000;
  int max_depth = 200;
  int max_primes = 8;
  int max_exponent = 64;  // |n| in x^n for numeric n
};

struct Resolver {
  // A name (with `primes` trailing primes) not followed by '('. Throw
  // ParseError for unknown names.
  std::function<GiNaC::ex(const std::string& name, int primes, std::size_t offset)> symbol;
  // name(args) where name is not a built-in function (x(0) in conditions).
  // Empty: such calls are errors.
  std::function<GiNaC::ex(const std::string& name, int primes, const std::vector<GiNaC::ex>& args,
                          std::size_t offset)>
      call;
};

// Parses "expr". Throws ParseError.
GiNaC::ex ParseExpression(const std::string& text, const Resolver& resolver,
                          const ParseLimits& limits = {});
// Parses "lhs = rhs" (or "expr", meaning expr = 0) and returns lhs - rhs.
GiNaC::ex ParseEquation(const std::string& text, const Resolver& resolver,
                        const ParseLimits& limits = {});

// Built-in function names the parser accepts, and those it refuses as not
// smooth (abs, floor, ...): names a model may not use for its own symbols.
bool IsBuiltinFunctionName(const std::string& name);
bool IsNonSmoothFunctionName(const std::string& name);
bool IsValidIdentifier(const std::string& name);

// Exact rational of a decimal literal ("1.5e-3"); false (with a reason) when
// it is not a plain number or is out of the double range.
bool DecimalToRational(const std::string& text, GiNaC::numeric* value, std::string* why);
// Exact rational of the shortest decimal that round-trips `value` (1.5 -> 3/2,
// 0.1 -> 1/10). value must be finite.
GiNaC::numeric RationalFromDouble(double value);

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_EXPRESSION_PARSER_H_
