#include "rmhb/model/model_error.h"

namespace rmhb::model {
namespace {

std::string Format(const std::string& message, const SourceLocation& where) {
  std::string prefix;
  if (!where.file.empty()) prefix = where.file + ":";
  if (where.line > 0) {
    prefix += std::to_string(where.line) + ":";
    if (where.column > 0) prefix += std::to_string(where.column) + ":";
  }
  return prefix.empty() ? message : prefix + " " + message;
}

}  // namespace

SourceLocation SourceLocation::Shifted(int offset) const {
  SourceLocation s = *this;
  if (s.column > 0) s.column += offset;
  return s;
}

ModelError::ModelError(const std::string& message, const SourceLocation& where,
                       const std::string& symbol)
    : std::runtime_error(Format(message, where)),
      message_(message),
      where_(where),
      symbol_(symbol) {}

}  // namespace rmhb::model
