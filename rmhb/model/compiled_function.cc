#include "rmhb/model/compiled_function.h"

#include <cmath>

namespace rmhb::model {

void CompiledFunction::Evaluate(const double* inputs, double* outputs,
                                std::vector<double>* work) const {
  Evaluate(inputs, outputs, work, nullptr);
}

void CompiledFunction::SwitchArguments(const std::vector<double>& work, double* arguments) const {
  for (std::size_t k = 0; k < switches_.size(); ++k) arguments[k] = work[code_[switches_[k]].a];
}

void CompiledFunction::Evaluate(const double* inputs, double* outputs, std::vector<double>* work,
                                const signed char* modes) const {
  if (work->size() < code_.size()) work->resize(code_.size());
  double* r = work->data();
  const int size = static_cast<int>(code_.size());
  for (int i = 0; i < size; ++i) {
    const Instruction& in = code_[i];
    switch (in.op) {
      case Op::kConst: r[i] = in.value; break;
      case Op::kInput: r[i] = inputs[in.a]; break;
      case Op::kAdd: r[i] = r[in.a] + r[in.b]; break;
      case Op::kSub: r[i] = r[in.a] - r[in.b]; break;
      case Op::kMul: r[i] = r[in.a] * r[in.b]; break;
      case Op::kDiv: r[i] = r[in.a] / r[in.b]; break;
      case Op::kNeg: r[i] = -r[in.a]; break;
      case Op::kPowInt: {
        const double x = r[in.a];
        int n = in.n < 0 ? -in.n : in.n;
        double result = 1.0, base = x;
        while (n) {
          if (n & 1) result *= base;
          base *= base;
          n >>= 1;
        }
        r[i] = in.n < 0 ? 1.0 / result : result;
        break;
      }
      case Op::kPowReal: r[i] = std::pow(r[in.a], r[in.b]); break;
      case Op::kSqrt: r[i] = std::sqrt(r[in.a]); break;
      case Op::kRealRoot: {
        // x^(p/q) with q odd, real for negative x: sign(x)^p |x|^(p/q).
        const double x = r[in.a];
        const double m = std::pow(std::fabs(x), in.value);
        r[i] = (x < 0 && (in.n & 1)) ? -m : m;
        break;
      }
      case Op::kSin: r[i] = std::sin(r[in.a]); break;
      case Op::kCos: r[i] = std::cos(r[in.a]); break;
      case Op::kTan: r[i] = std::tan(r[in.a]); break;
      case Op::kExp: r[i] = std::exp(r[in.a]); break;
      case Op::kLog: r[i] = std::log(r[in.a]); break;
      case Op::kAsin: r[i] = std::asin(r[in.a]); break;
      case Op::kAcos: r[i] = std::acos(r[in.a]); break;
      case Op::kAtan: r[i] = std::atan(r[in.a]); break;
      case Op::kSinh: r[i] = std::sinh(r[in.a]); break;
      case Op::kCosh: r[i] = std::cosh(r[in.a]); break;
      case Op::kTanh: r[i] = std::tanh(r[in.a]); break;
      case Op::kRamp: {
        const double x = r[in.a];
        r[i] = (modes ? modes[in.n] > 0 : x > 0) ? x : 0.0;
        break;
      }
      case Op::kHeaviside: r[i] = (modes ? modes[in.n] > 0 : r[in.a] >= 0) ? 1.0 : 0.0; break;
      case Op::kSign: {
        const double x = r[in.a];
        r[i] = modes ? double(modes[in.n]) : double((x > 0) - (x < 0));
        break;
      }
    }
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) outputs[k] = r[outputs_[k]];
}

std::vector<double> CompiledFunction::operator()(const std::vector<double>& inputs) const {
  std::vector<double> out(outputs_.size()), work;
  Evaluate(inputs.data(), out.data(), &work);
  return out;
}

}  // namespace rmhb::model
