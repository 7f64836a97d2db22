#include "rmhb/polynomial.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace rmhb {
namespace {

std::vector<int> Trimmed(std::vector<int> h) {
  while (!h.empty() && h.back() == 0) h.pop_back();
  return h;
}

// cos/sin products expand into sums and differences of harmonics.
std::vector<int> Combine(const std::vector<int>& a, const std::vector<int>& b, int sign) {
  std::vector<int> r(std::max(a.size(), b.size()), 0);
  for (size_t i = 0; i < a.size(); ++i) r[i] += a[i];
  for (size_t i = 0; i < b.size(); ++i) r[i] += sign * b[i];
  return Trimmed(r);
}

// Canonical form: the first non-zero entry positive (cos is even, sin odd).
// Returns the sign to apply to a sin coefficient.
int Canonicalize(TimeFunction* f) {
  f->harmonic = Trimmed(f->harmonic);
  if (f->harmonic.empty()) {
    if (f->kind == TimeFunction::Kind::kSin) return 0;  // sin(0) = 0
    f->kind = TimeFunction::Kind::kOne;
    return 1;
  }
  auto first = std::find_if(f->harmonic.begin(), f->harmonic.end(), [](int v) { return v != 0; });
  if (*first < 0) {
    for (int& v : f->harmonic) v = -v;
    return f->kind == TimeFunction::Kind::kSin ? -1 : 1;
  }
  return 1;
}

// Product of two time functions as a sum of (coefficient, function).
std::vector<std::pair<double, TimeFunction>> Multiply(const TimeFunction& a,
                                                      const TimeFunction& b) {
  using K = TimeFunction::Kind;
  if (a.kind == K::kOne) return {{1.0, b}};
  if (b.kind == K::kOne) return {{1.0, a}};
  TimeFunction diff{K::kCos, Combine(a.harmonic, b.harmonic, -1)};
  TimeFunction sum{K::kCos, Combine(a.harmonic, b.harmonic, +1)};
  if (a.kind == K::kCos && b.kind == K::kCos) return {{0.5, diff}, {0.5, sum}};
  if (a.kind == K::kSin && b.kind == K::kSin) return {{0.5, diff}, {-0.5, sum}};
  // sin(a)cos(b) = (sin(a+b) + sin(a-b))/2
  const TimeFunction& s = a.kind == K::kSin ? a : b;
  const TimeFunction& c = a.kind == K::kSin ? b : a;
  return {{0.5, {K::kSin, Combine(s.harmonic, c.harmonic, +1)}},
          {0.5, {K::kSin, Combine(s.harmonic, c.harmonic, -1)}}};
}

}  // namespace

int TimeFunction::Reach(int base) const {
  if (kind == Kind::kOne || base >= static_cast<int>(harmonic.size())) return 0;
  return std::abs(harmonic[base]);
}

bool TimeFunction::operator<(const TimeFunction& o) const {
  if (kind != o.kind) return kind < o.kind;
  return harmonic < o.harmonic;
}
bool TimeFunction::operator==(const TimeFunction& o) const {
  return kind == o.kind && harmonic == o.harmonic;
}

int Monomial::Degree() const {
  int d = 0;
  for (const auto& f : factors) d += f.second;
  return d;
}

bool Monomial::operator<(const Monomial& o) const {
  if (factors != o.factors) return factors < o.factors;
  return time < o.time;
}

Polynomial::Polynomial(double constant) {
  if (constant != 0.0) terms_[Monomial{}] = constant;
}

Polynomial Polynomial::Variable(int j) {
  if (j < 0) throw std::invalid_argument("Polynomial::Variable: negative index");
  Polynomial p;
  p.terms_[Monomial{{{Slot{j, 0}, 1}}, {}}] = 1.0;
  return p;
}

Polynomial Polynomial::Derivative(int j) {
  if (j < 0) throw std::invalid_argument("Polynomial::Derivative: negative index");
  Polynomial p;
  p.terms_[Monomial{{{Slot{j, 1}, 1}}, {}}] = 1.0;
  return p;
}

Polynomial Polynomial::Cos(std::vector<int> harmonic, double amplitude) {
  Polynomial p;
  Monomial m;
  m.time = {TimeFunction::Kind::kCos, std::move(harmonic)};
  p.Add(m, amplitude);
  return p;
}

Polynomial Polynomial::Sin(std::vector<int> harmonic, double amplitude) {
  Polynomial p;
  Monomial m;
  m.time = {TimeFunction::Kind::kSin, std::move(harmonic)};
  p.Add(m, amplitude);
  return p;
}

void Polynomial::Add(const Monomial& m, double c) {
  Monomial key = m;
  const int sign = Canonicalize(&key.time);
  if (sign == 0 || c == 0.0) return;
  double& v = terms_[key];
  v += sign * c;
  if (v == 0.0) terms_.erase(key);
}

int Polynomial::Degree() const {
  int d = 0;
  for (const auto& [m, c] : terms_) d = std::max(d, m.Degree());
  return d;
}

bool Polynomial::HasDerivative() const {
  for (const auto& [m, c] : terms_)
    for (const auto& f : m.factors)
      if (f.first.derivative > 0) return true;
  return false;
}

int Polynomial::MaxVariable() const {
  int j = -1;
  for (const auto& [m, c] : terms_)
    for (const auto& f : m.factors) j = std::max(j, f.first.variable);
  return j;
}

Polynomial& Polynomial::operator+=(const Polynomial& p) {
  for (const auto& [m, c] : p.terms_) Add(m, c);
  return *this;
}

Polynomial& Polynomial::operator-=(const Polynomial& p) {
  for (const auto& [m, c] : p.terms_) Add(m, -c);
  return *this;
}

Polynomial& Polynomial::operator*=(const Polynomial& p) {
  Polynomial r;
  for (const auto& [ma, ca] : terms_) {
    for (const auto& [mb, cb] : p.terms_) {
      Monomial m;
      std::map<Slot, int> powers;
      for (const auto& f : ma.factors) powers[f.first] += f.second;
      for (const auto& f : mb.factors) powers[f.first] += f.second;
      m.factors.assign(powers.begin(), powers.end());
      for (const auto& [k, tf] : Multiply(ma.time, mb.time)) {
        m.time = tf;
        r.Add(m, ca * cb * k);
      }
    }
  }
  terms_ = std::move(r.terms_);
  return *this;
}

Polynomial Polynomial::operator-() const {
  Polynomial r;
  r -= *this;
  return r;
}

std::string Polynomial::ToString(const std::vector<std::string>& names) const {
  if (terms_.empty()) return "0";
  std::ostringstream out;
  out.precision(12);
  bool first = true;
  for (const auto& [m, c] : terms_) {
    double mag = std::abs(c);
    out << (c < 0 ? (first ? "-" : " - ") : (first ? "" : " + "));
    first = false;
    std::vector<std::string> parts;
    if (mag != 1.0 || (m.factors.empty() && m.time.kind == TimeFunction::Kind::kOne)) {
      std::ostringstream num;
      num.precision(12);
      num << mag;
      parts.push_back(num.str());
    }
    for (const auto& [slot, power] : m.factors) {
      std::string s = slot.variable < static_cast<int>(names.size())
                          ? names[slot.variable]
                          : "z" + std::to_string(slot.variable);
      if (slot.derivative) s += "'";
      if (power > 1) s += "^" + std::to_string(power);
      parts.push_back(s);
    }
    if (m.time.kind != TimeFunction::Kind::kOne) {
      std::string arg;
      for (size_t i = 0; i < m.time.harmonic.size(); ++i) {
        int h = m.time.harmonic[i];
        if (h == 0) continue;
        std::string w = m.time.harmonic.size() == 1 ? "w" : "w" + std::to_string(i + 1);
        if (!arg.empty()) arg += h > 0 ? " + " : " - ";
        else if (h < 0) arg += "-";
        if (std::abs(h) != 1) arg += std::to_string(std::abs(h)) + " ";
        arg += w;
      }
      parts.push_back(std::string(m.time.kind == TimeFunction::Kind::kCos ? "cos" : "sin") +
                      "((" + arg + ") t)");
    }
    for (size_t i = 0; i < parts.size(); ++i) out << (i ? "*" : "") << parts[i];
  }
  return out.str();
}

Polynomial operator+(Polynomial a, const Polynomial& b) { return a += b; }
Polynomial operator-(Polynomial a, const Polynomial& b) { return a -= b; }
Polynomial operator*(Polynomial a, const Polynomial& b) { return a *= b; }

Polynomial Pow(const Polynomial& p, int n) {
  if (n < 0) throw std::invalid_argument("Pow: negative exponent");
  Polynomial r(1.0);
  for (int i = 0; i < n; ++i) r *= p;
  return r;
}

}  // namespace rmhb
