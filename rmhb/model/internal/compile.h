#ifndef RMHB_MODEL_INTERNAL_COMPILE_H_
#define RMHB_MODEL_INTERNAL_COMPILE_H_

// GiNaC expressions -> CompiledFunction.

#include <string>
#include <vector>

#include <ginac/ginac.h>

#include "rmhb/model/compiled_function.h"

namespace rmhb::model::internal {

// Compiles `outputs` as functions of `inputs` (in that order). Constant
// subtrees are folded. Throws std::invalid_argument naming an expression the
// tape cannot evaluate (a symbol that is not an input, an unknown function).
CompiledFunction Compile(const std::vector<GiNaC::ex>& outputs,
                         const std::vector<GiNaC::ex>& inputs);

// Evaluates a constant expression (no symbols) to a double; throws
// std::invalid_argument when it is not real and finite.
double EvaluateConstant(const GiNaC::ex& e);

// GiNaC's printed form of e.
std::string Str(const GiNaC::ex& e);

}  // namespace rmhb::model::internal

#endif  // RMHB_MODEL_INTERNAL_COMPILE_H_
