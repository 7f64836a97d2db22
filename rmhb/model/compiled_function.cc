#include "rmhb/model/compiled_function.h"

#include <algorithm>
#include <cmath>

namespace rmhb::model {
namespace {

// The operations with a body, shared by Evaluate and EvaluateMany so that
// both give the same bits by construction.
double PowInt(double x, int power) {
  int n = power < 0 ? -power : power;
  double result = 1.0, base = x;
  while (n) {
    if (n & 1) result *= base;
    base *= base;
    n >>= 1;
  }
  return power < 0 ? 1.0 / result : result;
}

// x^(p/q) with q odd, real for negative x: sign(x)^p |x|^(p/q).
double RealRoot(double x, double power, bool odd_numerator) {
  const double m = std::pow(std::fabs(x), power);
  return (x < 0 && odd_numerator) ? -m : m;
}

double Sign(double x) { return double((x > 0) - (x < 0)); }

template <typename F>
void Map1(long count, const double* a, double* r, F f) {
  for (long t = 0; t < count; ++t) r[t] = f(a[t]);
}

template <typename F>
void Map2(long count, const double* a, const double* b, double* r, F f) {
  for (long t = 0; t < count; ++t) r[t] = f(a[t], b[t]);
}

}  // namespace

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
      case Op::kPowInt: r[i] = PowInt(r[in.a], in.n); break;
      case Op::kPowReal: r[i] = std::pow(r[in.a], r[in.b]); break;
      case Op::kSqrt: r[i] = std::sqrt(r[in.a]); break;
      case Op::kRealRoot: r[i] = RealRoot(r[in.a], in.value, in.n & 1); break;
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
      case Op::kSign: r[i] = modes ? double(modes[in.n]) : Sign(r[in.a]); break;
    }
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) outputs[k] = r[outputs_[k]];
}


void CompiledFunction::EvaluateMany(long count, const double* inputs, long input_stride,
                                    double* outputs, long output_stride,
                                    std::vector<double>* work) const {
  const std::size_t needed = code_.size() * static_cast<std::size_t>(count);
  if (work->size() < needed) work->resize(needed);
  double* w = work->data();
  auto reg = [&](int i) { return w + static_cast<long>(i) * count; };
  const int size = static_cast<int>(code_.size());
  for (int i = 0; i < size; ++i) {
    const Instruction& in = code_[i];
    double* r = reg(i);
    const double* a = in.op == Op::kConst || in.op == Op::kInput ? nullptr : reg(in.a);
    switch (in.op) {
      case Op::kConst: std::fill(r, r + count, in.value); break;
      case Op::kInput: std::copy(inputs + in.a * input_stride, inputs + in.a * input_stride + count, r); break;
      case Op::kAdd: Map2(count, a, reg(in.b), r, [](double x, double y) { return x + y; }); break;
      case Op::kSub: Map2(count, a, reg(in.b), r, [](double x, double y) { return x - y; }); break;
      case Op::kMul: Map2(count, a, reg(in.b), r, [](double x, double y) { return x * y; }); break;
      case Op::kDiv: Map2(count, a, reg(in.b), r, [](double x, double y) { return x / y; }); break;
      case Op::kNeg: Map1(count, a, r, [](double x) { return -x; }); break;
      case Op::kPowInt: {
        const int power = in.n;
        Map1(count, a, r, [power](double x) { return PowInt(x, power); });
        break;
      }
      case Op::kPowReal: Map2(count, a, reg(in.b), r, [](double x, double y) { return std::pow(x, y); }); break;
      case Op::kSqrt: Map1(count, a, r, [](double x) { return std::sqrt(x); }); break;
      case Op::kRealRoot: {
        const double p = in.value;
        const bool odd = in.n & 1;
        Map1(count, a, r, [p, odd](double x) { return RealRoot(x, p, odd); });
        break;
      }
      case Op::kSin: Map1(count, a, r, [](double x) { return std::sin(x); }); break;
      case Op::kCos: Map1(count, a, r, [](double x) { return std::cos(x); }); break;
      case Op::kTan: Map1(count, a, r, [](double x) { return std::tan(x); }); break;
      case Op::kExp: Map1(count, a, r, [](double x) { return std::exp(x); }); break;
      case Op::kLog: Map1(count, a, r, [](double x) { return std::log(x); }); break;
      case Op::kAsin: Map1(count, a, r, [](double x) { return std::asin(x); }); break;
      case Op::kAcos: Map1(count, a, r, [](double x) { return std::acos(x); }); break;
      case Op::kAtan: Map1(count, a, r, [](double x) { return std::atan(x); }); break;
      case Op::kSinh: Map1(count, a, r, [](double x) { return std::sinh(x); }); break;
      case Op::kCosh: Map1(count, a, r, [](double x) { return std::cosh(x); }); break;
      case Op::kTanh: Map1(count, a, r, [](double x) { return std::tanh(x); }); break;
      case Op::kRamp: Map1(count, a, r, [](double x) { return x > 0 ? x : 0.0; }); break;
      case Op::kHeaviside: Map1(count, a, r, [](double x) { return x >= 0 ? 1.0 : 0.0; }); break;
      case Op::kSign: Map1(count, a, r, Sign); break;
    }
  }
  for (std::size_t k = 0; k < outputs_.size(); ++k) {
    const double* r = reg(outputs_[k]);
    std::copy(r, r + count, outputs + static_cast<long>(k) * output_stride);
  }
}

std::vector<double> CompiledFunction::operator()(const std::vector<double>& inputs) const {
  std::vector<double> out(outputs_.size()), work;
  Evaluate(inputs.data(), out.data(), &work);
  return out;
}

}  // namespace rmhb::model
