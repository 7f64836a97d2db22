#ifndef RMHB_MODEL_TAYLOR_EXPANSION_H_
#define RMHB_MODEL_TAYLOR_EXPANSION_H_

// The classical alternative to the exact recast (the paper's "RHB-Taylor",
// Table 3): replace the nonlinear functions of a model by their Taylor
// polynomials about the origin of the state, so that the system is
// polynomial without auxiliary variables, of degree phi = the Taylor order
// (M > (order + 1) N samples for RHB: 401 for order 15 and N = 25). The
// truncation is an error of the model itself that no number of harmonics
// removes: with theta0 = 1.5, sin's remainder after order 15 is
// 1.5^17 / 17! ~ 3e-12, so RHB-Taylor stalls there while the exact recast
// goes on to round-off.
//
// Done symbolically (GiNaC series): every derivative symbol s of every
// variable becomes eps * s, each equation is expanded in eps to order
// `order`, and eps = 1. That is the multivariate Taylor polynomial of total
// degree <= order; terms already polynomial of lower degree are exact, and
// harmonic forcing (no state in it) is kept as it is.

#include "rmhb/model/model_definition.h"

namespace rmhb::model {

// The model with its equations replaced by their Taylor polynomials of total
// degree `order` (>= 1) about the zero state. Conditions, initial state and
// guess are unchanged; the name gets a "-taylor<order>" suffix. Throws
// ModelError (located at the equation) when an equation has no Taylor
// expansion about zero (a pole or branch point there: 1/R, sqrt(x)).
ModelDefinition TaylorExpanded(const ModelDefinition& model, int order);

// Whether any equation contains a non-polynomial function of the state
// (sin, exp, a root, a quotient, ...): only then does a Taylor column say
// anything.
bool HasNonPolynomialTerms(const ModelDefinition& model);

}  // namespace rmhb::model

#endif  // RMHB_MODEL_TAYLOR_EXPANSION_H_
