#include "rmhb/model/internal/compile.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "rmhb/model/internal/symbolic_tools.h"

namespace rmhb::model::internal {

using GiNaC::ex;

std::string Str(const ex& e) {
  std::ostringstream out;
  out << e;
  return out.str();
}

namespace {

// At most ~80 characters of an expression, for messages.
std::string Short(const ex& e) {
  std::string s = Str(e);
  return s.size() <= 80 ? s : s.substr(0, 40) + " ... " + s.substr(s.size() - 20);
}

}  // namespace

double EvaluateConstant(const ex& e) {
  ex v;
  try {
    v = e.evalf();
  } catch (const std::exception& err) {
    throw std::invalid_argument("cannot evaluate " + Short(e) + ": " + err.what());
  }
  if (!GiNaC::is_a<GiNaC::numeric>(v))
    throw std::invalid_argument("'" + Short(e) + "' is not a number");
  const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(v);
  if (!n.is_real()) {
    // GiNaC takes the principal (complex) root of a negative number; the
    // recast and the tapes use the real odd root, (-8)^(1/3) = -2.
    double d = std::numeric_limits<double>::quiet_NaN();
    if (!GiNaC::is_a<GiNaC::numeric>(e)) {  // a complex number itself stays complex
      try {
        d = Compile({e}, {})(std::vector<double>{})[0];
      } catch (const std::exception&) {
      }
    }
    if (std::isfinite(d)) return d;
    throw std::invalid_argument("'" + Short(e) + "' is not real");
  }
  double d;
  try {
    d = n.to_double();
  } catch (const std::exception&) {
    throw std::invalid_argument("'" + Short(e) + "' is beyond the range of double");
  }
  if (!std::isfinite(d))
    throw std::invalid_argument("'" + Short(e) + "' is beyond the range of double");
  return d;
}

class TapeBuilder {
 public:
  using Op = CompiledFunction::Op;
  using Instruction = CompiledFunction::Instruction;

  explicit TapeBuilder(const std::vector<ex>& inputs) {
    f_.num_inputs_ = static_cast<int>(inputs.size());
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      if (!GiNaC::is_a<GiNaC::symbol>(inputs[i]))
        throw std::invalid_argument("Compile: inputs must be symbols");
      Instruction in{Op::kInput};
      in.a = static_cast<int>(i);
      memo_[inputs[i]] = Emit(in);
    }
  }

  void AddOutput(const ex& e) { f_.outputs_.push_back(Node(e)); }
  CompiledFunction Take() { return std::move(f_); }

 private:
  int Emit(const Instruction& in) {
    f_.code_.push_back(in);
    return static_cast<int>(f_.code_.size()) - 1;
  }
  int Constant(double v) {
    // Keyed by the bit pattern: NaN and -0.0 are distinct constants (a map
    // of doubles would take NaN as equivalent to every key).
    std::uint64_t bits;
    std::memcpy(&bits, &v, sizeof bits);
    auto it = constants_.find(bits);
    if (it != constants_.end()) return it->second;
    Instruction in{Op::kConst};
    in.value = v;
    const int r = Emit(in);
    constants_[bits] = r;
    return r;
  }
  bool IsConst(int r) const { return f_.code_[r].op == Op::kConst; }
  // Emits an instruction; folds it when every operand is constant.
  int Op1(Op op, int a, int n = 0, double value = 0) {
    Instruction in{op};
    in.a = a;
    in.n = n;
    in.value = value;
    if (IsConst(a)) return Fold(in);
    return Emit(in);
  }
  int Op2(Op op, int a, int b) {
    Instruction in{op};
    in.a = a;
    in.b = b;
    if (IsConst(a) && IsConst(b)) return Fold(in);
    return Emit(in);
  }
  int Fold(const Instruction& in) {
    // Evaluate the single instruction on a scratch tape of constants.
    CompiledFunction scratch;
    Instruction a{Op::kConst}, b{Op::kConst};
    a.value = f_.code_[in.a].value;
    scratch.code_.push_back(a);
    Instruction copy = in;
    copy.a = 0;
    if (in.b >= 0) {
      b.value = f_.code_[in.b].value;
      scratch.code_.push_back(b);
      copy.b = 1;
    }
    scratch.code_.push_back(copy);
    scratch.outputs_.push_back(static_cast<int>(scratch.code_.size()) - 1);
    double out;
    std::vector<double> work;
    scratch.Evaluate(nullptr, &out, &work);
    return Constant(out);
  }

  int Node(const ex& e) {
    auto it = memo_.find(e);
    if (it != memo_.end()) return it->second;
    const int r = Build(e);
    memo_[e] = r;
    return r;
  }

  int Build(const ex& e) {
    using GiNaC::is_a;
    if (is_a<GiNaC::numeric>(e) || is_a<GiNaC::constant>(e)) return Constant(EvaluateConstant(e));
    if (is_a<GiNaC::symbol>(e))
      throw std::invalid_argument("the symbol '" + Str(e) + "' is not an input here");
    if (is_a<GiNaC::add>(e) || is_a<GiNaC::mul>(e)) {
      // GiNaC orders operands by hash values that depend on where the type
      // names were loaded (ASLR): sum them in a printed order instead, so
      // that the floating-point result is the same in every run.
      std::vector<std::pair<std::string, ex>> operands;
      for (std::size_t i = 0; i < e.nops(); ++i) operands.emplace_back(Print(e.op(i)), e.op(i));
      std::stable_sort(operands.begin(), operands.end(),
                       [](const auto& a, const auto& b) { return a.first < b.first; });
      const Op op = is_a<GiNaC::add>(e) ? Op::kAdd : Op::kMul;
      int acc = Node(operands[0].second);
      for (std::size_t i = 1; i < operands.size(); ++i) acc = Op2(op, acc, Node(operands[i].second));
      return acc;
    }
    if (is_a<GiNaC::power>(e)) {
      const ex& base = e.op(0);
      const ex& exponent = e.op(1);
      if (is_a<GiNaC::numeric>(exponent)) {
        const GiNaC::numeric& n = GiNaC::ex_to<GiNaC::numeric>(exponent);
        const int b = Node(base);
        if (n.is_integer()) {
          if (n == -1) return Op2(Op::kDiv, Constant(1.0), b);
          return Op1(Op::kPowInt, b, n.to_int());
        }
        if (n.is_rational()) {
          if (n == GiNaC::numeric(1, 2)) return Op1(Op::kSqrt, b);
          if (n == GiNaC::numeric(-1, 2)) return Op2(Op::kDiv, Constant(1.0), Op1(Op::kSqrt, b));
          // b^(p/2) = b^((p - 1)/2) sqrt(b): a square root and a product or
          // two instead of pow's log and exp ((1 - x'^2)^(3/2), the
          // relativistic oscillator: pow was 8 % of its solve).
          if (n.denom() == 2) {
            const int power = (n.numer().to_int() - 1) / 2;  // p odd: exact
            const int whole = power == 1 ? b : Op1(Op::kPowInt, b, power);
            return Op2(Op::kMul, whole, Op1(Op::kSqrt, b));
          }
          if (n.denom().is_odd())
            return Op1(Op::kRealRoot, b, n.numer().to_int(), n.to_double());
        }
        return Op2(Op::kPowReal, b, Constant(EvaluateConstant(exponent)));
      }
      return Op2(Op::kPowReal, Node(base), Node(exponent));
    }
    if (is_a<GiNaC::function>(e)) {
      const std::string name = GiNaC::ex_to<GiNaC::function>(e).get_name();
      static const std::map<std::string, Op> ops = {
          {"sin", Op::kSin},   {"cos", Op::kCos},   {"tan", Op::kTan},   {"exp", Op::kExp},
          {"log", Op::kLog},   {"asin", Op::kAsin}, {"acos", Op::kAcos}, {"atan", Op::kAtan},
          {"sinh", Op::kSinh}, {"cosh", Op::kCosh}, {"tanh", Op::kTanh}};
      static const std::map<std::string, Op> switches = {
          {"ramp", Op::kRamp}, {"heaviside", Op::kHeaviside}, {"sgn", Op::kSign}};
      if (auto sw = switches.find(name); sw != switches.end() && e.nops() == 1) {
        const int a = Node(e.op(0));
        if (IsConst(a)) return Op1(sw->second, a);  // folded: no switch
        Instruction in{sw->second};
        in.a = a;
        in.n = static_cast<int>(f_.switches_.size());
        const int r = Emit(in);
        f_.switches_.push_back(r);
        return r;
      }
      auto op = ops.find(name);
      if (op == ops.end() || e.nops() != 1)
        throw std::invalid_argument("cannot compile the function " + Str(e));
      return Op1(op->second, Node(e.op(0)));
    }
    throw std::invalid_argument("cannot compile " + Str(e));
  }

  CompiledFunction f_;
  std::map<ex, int, GiNaC::ex_is_less> memo_;
  std::map<std::uint64_t, int> constants_;
};

CompiledFunction Compile(const std::vector<ex>& outputs, const std::vector<ex>& inputs) {
  TapeBuilder builder(inputs);
  for (const ex& e : outputs) builder.AddOutput(e);
  return builder.Take();
}

}  // namespace rmhb::model::internal
