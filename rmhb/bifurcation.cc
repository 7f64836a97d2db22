#include "rmhb/bifurcation.h"

#include <cmath>
#include <cstdio>
#include <limits>

namespace rmhb {
namespace {

bool IsReal(std::complex<double> mu) { return std::abs(mu.imag()) <= kRealMultiplierTolerance * (1 + std::abs(mu)); }

}  // namespace

const char* ToString(BifurcationType type) {
  switch (type) {
    case BifurcationType::kFold: return "fold";
    case BifurcationType::kBranchPoint: return "branch_point";
    case BifurcationType::kPeriodDoubling: return "period_doubling";
    case BifurcationType::kNeimarkSacker: return "neimark_sacker";
  }
  return "unknown";
}

const char* ShortName(BifurcationType type) {
  switch (type) {
    case BifurcationType::kFold: return "fold";
    case BifurcationType::kBranchPoint: return "BP";
    case BifurcationType::kPeriodDoubling: return "PD";
    case BifurcationType::kNeimarkSacker: return "NS";
  }
  return "?";
}

TestFunctionSigns TestSigns(const Multipliers& mu, int trivial) {
  int below_plus = 0, below_minus = 0, torus = 0, pairs = 0;
  std::vector<double> reals;
  for (size_t i = 0; i < mu.size(); ++i) {
    if (static_cast<int>(i) == trivial) continue;
    if (IsReal(mu[i])) {
      const double r = mu[i].real();
      below_plus += r < 1;
      below_minus += r < -1;
      reals.push_back(r);
    } else if (mu[i].imag() > 0) {
      // One factor mu mu* - 1 = |mu|^2 - 1 per conjugate pair; the factors
      // pairing it with other multipliers come in conjugate pairs (> 0).
      torus += std::abs(mu[i]) < 1;
      pairs += std::abs(mu[i]) < 1;
    }
  }
  for (size_t i = 0; i < reals.size(); ++i)
    for (size_t j = i + 1; j < reals.size(); ++j) torus += reals[i] * reals[j] < 1;
  return {below_plus % 2 ? -1 : 1, below_minus % 2 ? -1 : 1, torus % 2 ? -1 : 1, pairs % 2 ? -1 : 1};
}

double JudgedModulus(const Multipliers& mu, int trivial, double band, bool* paired) {
  if (paired) *paired = false;
  int partner = -1;
  if (trivial >= 0)
    for (size_t i = 0; i < mu.size(); ++i)
      if (static_cast<int>(i) != trivial && IsReal(mu[i]) &&
          (partner < 0 || std::abs(mu[i] - mu[trivial]) < std::abs(mu[partner] - mu[trivial])))
        partner = static_cast<int>(i);
  const bool pair = partner >= 0 && std::abs(std::abs(mu[partner] * mu[trivial]) - 1) <= band;
  double largest = pair ? std::sqrt(std::abs(mu[partner] * mu[trivial])) : 0;
  for (size_t i = 0; i < mu.size(); ++i)
    if (static_cast<int>(i) != trivial && !(pair && static_cast<int>(i) == partner))
      largest = std::max(largest, std::abs(mu[i]));
  if (paired) *paired = pair;
  return largest;
}

bool CriticalMultiplier(const Multipliers& mu, int trivial, BifurcationType type, std::complex<double>* critical,
                        double* distance) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < mu.size(); ++i) {
    if (static_cast<int>(i) == trivial) continue;
    double d = 0;
    if (type == BifurcationType::kNeimarkSacker) {
      if (IsReal(mu[i]) || mu[i].imag() < 0) continue;
      d = std::abs(mu[i]) - 1;
    } else {
      if (!IsReal(mu[i])) continue;
      d = type == BifurcationType::kPeriodDoubling ? mu[i].real() + 1 : mu[i].real() - 1;
    }
    if (std::abs(d) < std::abs(best)) best = d, *critical = mu[i];
  }
  if (!std::isfinite(best)) return false;
  *distance = best;
  return true;
}

std::string BifurcationPoint::Describe(const std::string& name) const {
  char line[400];
  if (type == BifurcationType::kFold) {
    std::snprintf(line, sizeof line, "fold at %s = %.12g (d%s/ds = %.1e)", name.c_str(), parameter, name.c_str(),
                  distance);
    return line;
  }
  const char* what = type == BifurcationType::kBranchPoint     ? "branch point"
                     : type == BifurcationType::kPeriodDoubling ? "period doubling"
                                                                : "Neimark-Sacker";
  const char* test = type == BifurcationType::kNeimarkSacker    ? "|mu| - 1"
                     : type == BifurcationType::kPeriodDoubling ? "mu + 1"
                                                                : "mu - 1";
  if (!std::isfinite(distance)) {
    std::snprintf(line, sizeof line, "%s between %s = %.12g and the previous point: NOT located (no corrected point "
                  "with multipliers on the arc)", what, name.c_str(), parameter);
    return line;
  }
  std::snprintf(line, sizeof line, "%s at %s = %.12g: mu = %.10g%+.10gi (%s), %s: |%s| = %.1e %s %.0e", what,
                name.c_str(), parameter, multiplier.real(), multiplier.imag(), method.c_str(),
                located ? "located" : "NOT located", test, std::abs(distance), located ? "<=" : ">", tolerance);
  std::string out = line;
  if (Jump()) {
    std::snprintf(line, sizeof line, ", the multipliers jump across it within %.1e (a switching event such as "
                  "grazing)", parameter_bracket);
    return out + line;
  }
  if (std::isfinite(parameter_error)) {
    std::snprintf(line, sizeof line, ", %s within ~%.0e (last bracket %.1e wide)", name.c_str(), parameter_error,
                  parameter_bracket);
    out += line;
  }
  if (type == BifurcationType::kNeimarkSacker) {
    std::snprintf(line, sizeof line, "; new frequency w2 = %.10g", torus_frequency);
    out += line;
  }
  return out;
}

}  // namespace rmhb
