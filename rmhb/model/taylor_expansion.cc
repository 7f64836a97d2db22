#include "rmhb/model/taylor_expansion.h"

#include <memory>
#include <string>

#include <ginac/ginac.h>

#include "rmhb/model/internal/symbolic_model.h"
#include "rmhb/model/internal/symbolic_tools.h"

namespace rmhb::model {
namespace {

GiNaC::lst StateSymbols(const internal::SymbolicModel& symbolic) {
  GiNaC::lst symbols;
  for (const auto& chain : symbolic.derivatives)
    for (const auto& s : chain) symbols.append(s);
  return symbols;
}

}  // namespace

bool HasNonPolynomialTerms(const ModelDefinition& model) {
  if (!model.symbolic) return false;
  const GiNaC::lst symbols = StateSymbols(*model.symbolic);
  for (const auto& e : model.symbolic->equations)
    if (!e.expand().is_polynomial(symbols)) return true;
  return false;
}

ModelDefinition TaylorExpanded(const ModelDefinition& model, int order) {
  if (!model.symbolic) throw ModelError("TaylorExpanded: the model was not parsed", {model.source, 0, 0});
  if (order < 1) throw ModelError("Taylor order must be >= 1 (got " + std::to_string(order) + ")", {model.source, 0, 0});
  auto symbolic = std::make_shared<internal::SymbolicModel>(*model.symbolic);
  const GiNaC::lst symbols = StateSymbols(*symbolic);
  const GiNaC::symbol eps("taylor_eps");
  GiNaC::exmap scale;
  for (const auto& s : symbols) scale[s] = eps * s;
  ModelDefinition out = model;
  out.name = model.name + "-taylor" + std::to_string(order);
  for (size_t i = 0; i < symbolic->equations.size(); ++i) {
    const GiNaC::ex& e = symbolic->equations[i];
    const SourceLocation& where = model.equations[i].where;
    GiNaC::ex polynomial;
    try {
      const GiNaC::ex s = e.subs(scale).series(eps == 0, order + 1);
      polynomial = GiNaC::series_to_poly(s).subs(eps == 1).expand();
    } catch (const std::exception& err) {
      throw ModelError("equation " + std::to_string(i + 1) + " has no Taylor expansion about the zero state: " +
                           err.what(), where);
    }
    if (!polynomial.is_polynomial(symbols))
      throw ModelError("equation " + std::to_string(i + 1) +
                           " has no Taylor expansion about the zero state (a pole or branch point at 0)",
                       where);
    symbolic->equations[i] = polynomial;
    out.equations[i].text = internal::Print(polynomial) + " = 0";
  }
  out.symbolic = symbolic;
  return out;
}

}  // namespace rmhb::model
