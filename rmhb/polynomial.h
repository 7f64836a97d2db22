#ifndef RMHB_POLYNOMIAL_H_
#define RMHB_POLYNOMIAL_H_

// Polynomials in the states z_j, their first derivatives z_j', with known
// harmonic time functions cos(q.theta), sin(q.theta) (theta_i = w_i t) as
// coefficients. This is the only kind of nonlinearity the solver core sees:
// every elementary nonlinearity is recast into it first (METHOD.md s.4),
// because for polynomials Theorem 1 gives an alias-free sample count and the
// collocation equations are exactly classical harmonic balance.

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rmhb {

// A known time function multiplying a term.
struct TimeFunction {
  enum class Kind { kOne, kCos, kSin };
  Kind kind = Kind::kOne;
  // Integer combination of the base frequencies, one entry per base; a
  // shorter vector is padded with zeros.
  std::vector<int> harmonic;

  // Highest |harmonic| along base frequency `base`: how far this factor
  // shifts a product's spectrum, which the alias bound must count.
  int Reach(int base) const;
  bool operator<(const TimeFunction& other) const;
  bool operator==(const TimeFunction& other) const;
};

// z_j (derivative = 0) or z_j' (derivative = 1).
struct Slot {
  int variable = 0;
  int derivative = 0;
  bool operator<(const Slot& o) const {
    return variable != o.variable ? variable < o.variable : derivative < o.derivative;
  }
  bool operator==(const Slot& o) const {
    return variable == o.variable && derivative == o.derivative;
  }
};

struct Monomial {
  std::vector<std::pair<Slot, int>> factors;  // sorted by slot, powers >= 1
  TimeFunction time;

  int Degree() const;  // z' counts like z: it is a linear map of z's harmonics
  bool operator<(const Monomial& other) const;
};

class Polynomial {
 public:
  Polynomial() = default;
  Polynomial(double constant);  // NOLINT: implicit, so "2.0 * x - 1" reads naturally

  static Polynomial Variable(int j);
  static Polynomial Derivative(int j);
  static Polynomial Cos(std::vector<int> harmonic, double amplitude = 1.0);
  static Polynomial Sin(std::vector<int> harmonic, double amplitude = 1.0);

  const std::map<Monomial, double>& terms() const { return terms_; }
  int Degree() const;
  bool HasDerivative() const;
  bool IsZero() const { return terms_.empty(); }
  // Largest variable index referenced, or -1.
  int MaxVariable() const;

  Polynomial& operator+=(const Polynomial& p);
  Polynomial& operator-=(const Polynomial& p);
  Polynomial& operator*=(const Polynomial& p);
  Polynomial operator-() const;

  // Readable form with the given variable names, e.g. "x' - v".
  std::string ToString(const std::vector<std::string>& names) const;

 private:
  void Add(const Monomial& m, double c);
  std::map<Monomial, double> terms_;
};

Polynomial operator+(Polynomial a, const Polynomial& b);
Polynomial operator-(Polynomial a, const Polynomial& b);
Polynomial operator*(Polynomial a, const Polynomial& b);
Polynomial Pow(const Polynomial& p, int n);

}  // namespace rmhb

#endif  // RMHB_POLYNOMIAL_H_
