#ifndef RMHB_MODEL_MODEL_ERROR_H_
#define RMHB_MODEL_MODEL_ERROR_H_

// The one error type of the model layer: anything wrong with a model file or
// its use (YAML syntax, unknown symbols, unsupported functions, a parameter
// override naming no parameter, ...) is reported as a ModelError that says
// where, in the compiler style editors understand:
//   pendulum.yaml:7:18: unknown symbol 'thta' in equation 1
// Line and column are 1-based; 0 means unknown (then they are left out).

#include <stdexcept>
#include <string>

namespace rmhb::model {

struct SourceLocation {
  std::string file;
  int line = 0;
  int column = 0;
  // The same place shifted `offset` characters to the right on its line.
  SourceLocation Shifted(int offset) const;
};

class ModelError : public std::runtime_error {
 public:
  explicit ModelError(const std::string& message, const SourceLocation& where = {},
                      const std::string& symbol = "");

  const std::string& message() const { return message_; }  // without the location
  const std::string& file() const { return where_.file; }
  int line() const { return where_.line; }
  int column() const { return where_.column; }
  const SourceLocation& where() const { return where_; }
  // The offending name when there is one ('thta', 'abs', a parameter name).
  const std::string& symbol() const { return symbol_; }

 private:
  std::string message_;
  SourceLocation where_;
  std::string symbol_;
};

}  // namespace rmhb::model

#endif  // RMHB_MODEL_MODEL_ERROR_H_
