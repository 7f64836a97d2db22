#include "rmhb/polynomial_system.h"

#include <algorithm>
#include <sstream>
#include <stdexcept>

namespace rmhb {

int PolynomialSystem::AddVariable(const std::string& name, VariableRole role,
                                  const std::string& definition) {
  if (name.empty()) throw std::invalid_argument("PolynomialSystem: empty variable name");
  if (IndexOf(name) >= 0)
    throw std::invalid_argument("PolynomialSystem: variable '" + name + "' declared twice");
  variables_.push_back({name, role, definition});
  return num_variables() - 1;
}

int PolynomialSystem::AddEquation(Polynomial lhs, bool balance_constant) {
  equations_.push_back({std::move(lhs), balance_constant, nullptr});
  return num_equations() - 1;
}

int PolynomialSystem::AddPointwiseEquation(PointwiseEquation equation) {
  if (!equation.evaluate) throw std::invalid_argument("PolynomialSystem: a pointwise equation needs an evaluator");
  Equation e;
  e.pointwise = std::make_shared<const PointwiseEquation>(std::move(equation));
  equations_.push_back(std::move(e));
  return num_equations() - 1;
}

bool PolynomialSystem::HasNonSmooth() const {
  for (const Equation& e : equations_)
    if (e.pointwise && e.pointwise->nonsmooth) return true;
  return false;
}

bool PolynomialSystem::HasPointwise() const {
  return std::any_of(equations_.begin(), equations_.end(),
                     [](const Equation& e) { return e.pointwise != nullptr; });
}

Polynomial PolynomialSystem::Var(int j) const {
  if (j < 0 || j >= num_variables())
    throw std::invalid_argument("PolynomialSystem: no variable with index " + std::to_string(j));
  return Polynomial::Variable(j);
}

int PolynomialSystem::IndexOf(const std::string& name) const {
  for (int j = 0; j < num_variables(); ++j)
    if (variables_[j].name == name) return j;
  return -1;
}

Polynomial PolynomialSystem::Var(const std::string& name) const {
  const int j = IndexOf(name);
  if (j < 0) throw std::invalid_argument("PolynomialSystem: unknown variable '" + name + "'");
  return Polynomial::Variable(j);
}

Polynomial PolynomialSystem::D(const std::string& name) const {
  const int j = IndexOf(name);
  if (j < 0) throw std::invalid_argument("PolynomialSystem: unknown variable '" + name + "'");
  return Polynomial::Derivative(j);
}

std::vector<std::string> PolynomialSystem::names() const {
  std::vector<std::string> n;
  for (const auto& v : variables_) n.push_back(v.name);
  return n;
}

int PolynomialSystem::Degree() const {
  int d = 0;
  for (const auto& e : equations_) d = std::max(d, e.lhs.Degree());
  return d;
}

int PolynomialSystem::ForcingReach(int base) const {
  int r = 0;
  for (const auto& e : equations_)
    for (const auto& [m, c] : e.lhs.terms()) r = std::max(r, m.time.Reach(base));
  return r;
}

int PolynomialSystem::AliasFreeSamples(int reach, int base) const {
  int m = 2 * reach + 1;  // the basis itself must be resolved
  for (const auto& e : equations_)
    for (const auto& [mono, c] : e.lhs.terms())
      m = std::max(m, (mono.Degree() + 1) * reach + mono.time.Reach(base) + 1);
  return m;
}

void PolynomialSystem::Validate() const {
  if (variables_.empty()) throw std::invalid_argument("PolynomialSystem: no variables");
  if (num_equations() != num_variables()) {
    std::ostringstream msg;
    msg << "PolynomialSystem: " << num_equations() << " equations for " << num_variables()
        << " variables; the system must be square";
    throw std::invalid_argument(msg.str());
  }
  for (int i = 0; i < num_equations(); ++i) {
    if (const auto& p = equations_[i].pointwise) {
      for (const Slot& slot : p->slots)
        if (slot.variable < 0 || slot.variable >= num_variables() || slot.derivative < 0 || slot.derivative > 1)
          throw std::invalid_argument("PolynomialSystem: pointwise equation " + std::to_string(i + 1) +
                                      " references an undeclared variable");
      continue;
    }
    if (equations_[i].lhs.IsZero())
      throw std::invalid_argument("PolynomialSystem: equation " + std::to_string(i + 1) +
                                  " is identically zero");
    if (equations_[i].lhs.MaxVariable() >= num_variables())
      throw std::invalid_argument("PolynomialSystem: equation " + std::to_string(i + 1) +
                                  " references an undeclared variable");
  }
  std::vector<bool> used(variables_.size(), false);
  for (const auto& e : equations_) {
    for (const auto& [m, c] : e.lhs.terms())
      for (const auto& f : m.factors) used[f.first.variable] = true;
    if (e.pointwise)
      for (const Slot& slot : e.pointwise->slots) used[slot.variable] = true;
  }
  for (int j = 0; j < num_variables(); ++j)
    if (!used[j])
      throw std::invalid_argument("PolynomialSystem: variable '" + variables_[j].name +
                                  "' appears in no equation");
}

std::string PolynomialSystem::ToString() const {
  std::ostringstream out;
  const auto n = names();
  out << "variables:";
  for (const auto& v : variables_) {
    out << " " << v.name;
    if (v.role == VariableRole::kAuxiliary)
      out << (v.definition.empty() ? "(aux)" : "(= " + v.definition + ")");
  }
  if (HasPointwise()) out << "\nequations (original, not polynomial):\n";
  else out << "\nequations (degree phi = " << Degree() << "):\n";
  for (const auto& e : equations_) {
    if (e.pointwise) {
      out << "  " << e.pointwise->text << "   [evaluated pointwise at the samples]\n";
      continue;
    }
    out << "  " << e.lhs.ToString(n) << " = 0";
    if (!e.balance_constant) out << "   [constant term not balanced; pinned at t = 0]";
    out << "\n";
  }
  return out.str();
}

}  // namespace rmhb
