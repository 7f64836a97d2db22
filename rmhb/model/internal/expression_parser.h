#ifndef RMHB_MODEL_INTERNAL_EXPRESSION_PARSER_H_
#define RMHB_MODEL_INTERNAL_EXPRESSION_PARSER_H_

// Natural-notation expressions -> GiNaC, by GiNaC's own parser
// (GiNaC::parser, strict mode, a symbol table and a prototype table of the
// supported functions). Three steps:
//
// 1. A pre-tokenizer splits the text into numbers, names with their primes
//    (x'' is one token, name "x" with 2 primes) and operators, and checks the
//    token sequence (balanced parentheses, an operator between operands, the
//    functions and their argument counts), so that every syntax error names
//    the place: GiNaC 1.8's parse_error carries a line but its column is
//    always 0, and some inputs crash or mislead it (`sin()` dereferences a
//    missing argument, `2^-1+x` reads as 2^(-1+x), `a^b^c` is refused).
//    Names are resolved by the caller's Resolver with their offset.
// 2. The tokens are rewritten into GiNaC-safe text: every name and number
//    becomes a placeholder symbol of the symbol table (so `x''`, `x'(0)`,
//    `I` or `Pi` typed by the user cannot collide with GiNaC's literals),
//    `**` becomes `^`, the operand of `^` and of a sign after an operator is
//    parenthesised. Each emitted character keeps the offset it came from.
// 3. GiNaC parses. Numbers are placeholders during the parse, so GiNaC cannot
//    evaluate 10^10^10 or 1/0 there; a post-parse walk substitutes them
//    bottom-up, refusing huge exponents, division by zero, complex or
//    out-of-range values and functions outside the supported set, and
//    reports at the offending number.
//
// Decimal literals become exact rationals (0.85 -> 17/20), so exponents like
// 3/2 or 1.5 are recognised as radicals by the recast. Hostile input is
// bounded before GiNaC sees it (length, nesting depth after rewriting,
// primes, exponent size, literal size).

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

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_EXPRESSION_PARSER_H_
