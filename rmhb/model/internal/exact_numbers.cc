#include "rmhb/model/internal/exact_numbers.h"

#include <cctype>
#include <charconv>
#include <cmath>

namespace rmhb::model::internal {

using GiNaC::numeric;

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
