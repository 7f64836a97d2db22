#ifndef RMHB_MODEL_INTERNAL_EXACT_NUMBERS_H_
#define RMHB_MODEL_INTERNAL_EXACT_NUMBERS_H_

// Decimal numbers as exact rationals (0.85 -> 17/20), so that exponents like
// 1.5 are recognised as radicals by the recast and parameter values enter the
// symbolic expressions without rounding.

#include <string>

#include <ginac/ginac.h>

namespace rmhb::model::internal {

// Exact rational of a decimal literal ("1.5e-3"); false (with a reason) when
// it is not a plain number, has more than 40 significant digits, or is out of
// the double range.
bool DecimalToRational(const std::string& text, GiNaC::numeric* value, std::string* why);
// Exact rational of the shortest decimal that round-trips `value` (1.5 -> 3/2,
// 0.1 -> 1/10). value must be finite.
GiNaC::numeric RationalFromDouble(double value);

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_EXACT_NUMBERS_H_
