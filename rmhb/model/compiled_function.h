#ifndef RMHB_MODEL_COMPILED_FUNCTION_H_
#define RMHB_MODEL_COMPILED_FUNCTION_H_

// A vector function R^n -> R^m compiled from symbolic expressions into a
// tape: a postorder list of operations on doubles over the expression DAG
// (shared subexpressions computed once), evaluated in a plain loop. The
// integrators call the original equations millions of times; walking GiNaC
// trees (reference counts, virtual dispatch, exact arithmetic) per call would
// dominate. Built by the model layer (see internal/compile.h); evaluation
// needs no GiNaC.
//
// Evaluation is const and writes only to the caller's work buffer, so one
// CompiledFunction may be shared; give every thread its own buffer.

#include <cstdint>
#include <vector>

namespace rmhb::model {

namespace internal {
class TapeBuilder;
}

class CompiledFunction {
 public:
  int num_inputs() const { return num_inputs_; }
  int num_outputs() const { return static_cast<int>(outputs_.size()); }
  int size() const { return static_cast<int>(code_.size()); }  // instructions

  // outputs[i] = f_i(inputs). `work` is resized to size() on first use.
  void Evaluate(const double* inputs, double* outputs, std::vector<double>* work) const;

  // Piecewise-smooth tapes (ramp, heaviside, sign: METHOD.md s.15). Each such
  // operation is a switch with an argument; by default it takes the branch
  // of its argument's sign. With `modes` (one per switch, +1 or -1) every
  // switch keeps the given branch whatever its argument: the smooth
  // continuation of one side, which event-located integration needs to
  // step up to a switching surface without crossing it. After an
  // evaluation, SwitchArguments reads every switch's argument off `work`.
  int num_switches() const { return static_cast<int>(switches_.size()); }
  void Evaluate(const double* inputs, double* outputs, std::vector<double>* work,
                const signed char* modes) const;
  void SwitchArguments(const std::vector<double>& work, double* arguments) const;
  // `count` points at once, instruction by instruction over all of them (the
  // switch on the operation once per instruction, not per point; the loops
  // vectorise): input k of point t at inputs[k * input_stride + t], output i
  // at outputs[i * output_stride + t] (column-major matrices). Switches take
  // their argument's side. `work` is resized to size() * count.
  void EvaluateMany(long count, const double* inputs, long input_stride, double* outputs,
                    long output_stride, std::vector<double>* work) const;
  // Convenience (allocates).
  std::vector<double> operator()(const std::vector<double>& inputs) const;

 private:
  friend class internal::TapeBuilder;
  enum class Op : std::uint8_t {
    kConst, kInput, kAdd, kSub, kMul, kDiv, kNeg, kPowInt, kPowReal, kSqrt, kRealRoot,
    kSin, kCos, kTan, kExp, kLog, kAsin, kAcos, kAtan, kSinh, kCosh, kTanh,
    kRamp, kHeaviside, kSign,  // switches: n is the switch's index
  };
  struct Instruction {
    Op op;
    int a = -1;  // operand registers
    int b = -1;
    int n = 0;         // integer exponent (kPowInt), root index (kRealRoot)
    double value = 0;  // constant (kConst), power (kRealRoot)
  };
  int num_inputs_ = 0;
  std::vector<Instruction> code_;
  std::vector<int> outputs_;  // register of each output
  std::vector<int> switches_;  // instruction of each switch
};

}  // namespace rmhb::model

#endif  // RMHB_MODEL_COMPILED_FUNCTION_H_
