#include "rmhb/harmonic_basis.h"

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <stdexcept>

namespace rmhb {
namespace {

bool Canonical(const std::vector<int>& k) {
  for (int v : k)
    if (v != 0) return v > 0;
  return false;  // zero is added separately
}

// All integer vectors in [-order, order]^d accepted by `keep`, canonical half,
// ordered by total degree so low harmonics come first.
std::vector<std::vector<int>> Enumerate(int d, int order,
                                        const std::function<bool(const std::vector<int>&)>& keep) {
  std::vector<std::vector<int>> out;
  std::vector<int> k(d, -order);
  while (true) {
    if (Canonical(k) && keep(k)) out.push_back(k);
    int i = d - 1;
    while (i >= 0 && k[i] == order) k[i--] = -order;
    if (i < 0) break;
    ++k[i];
  }
  auto l1 = [](const std::vector<int>& v) {
    int s = 0;
    for (int x : v) s += std::abs(x);
    return s;
  };
  std::stable_sort(out.begin(), out.end(),
                   [&](const auto& a, const auto& b) { return l1(a) < l1(b); });
  return out;
}

void CheckArguments(int num_bases, int order) {
  if (num_bases < 1 || num_bases > 3)
    throw std::invalid_argument("HarmonicBasis: number of base frequencies must be 1, 2 or 3");
  if (order < 1)
    throw std::invalid_argument("HarmonicBasis: order must be >= 1, got " + std::to_string(order));
  if (order > 100000) throw std::invalid_argument("HarmonicBasis: order is unreasonably large");
}

}  // namespace

HarmonicBasis HarmonicBasis::Periodic(int order) {
  CheckArguments(1, order);
  HarmonicBasis b(1, order, "periodic");
  for (int k = 0; k <= order; ++k) b.harmonics_->push_back({k});
  return b;
}

HarmonicBasis HarmonicBasis::Diamond(int num_bases, int order) {
  if (num_bases == 1) return Periodic(order);
  CheckArguments(num_bases, order);
  HarmonicBasis b(num_bases, order, "diamond");
  b.harmonics_->push_back(std::vector<int>(num_bases, 0));
  for (auto& k : Enumerate(num_bases, order, [order](const std::vector<int>& v) {
         int s = 0;
         for (int x : v) s += std::abs(x);
         return s <= order;
       }))
    b.harmonics_->push_back(k);
  return b;
}

HarmonicBasis HarmonicBasis::Box(int num_bases, int order) {
  if (num_bases == 1) return Periodic(order);
  CheckArguments(num_bases, order);
  HarmonicBasis b(num_bases, order, "box");
  b.harmonics_->push_back(std::vector<int>(num_bases, 0));
  for (auto& k : Enumerate(num_bases, order, [](const std::vector<int>&) { return true; }))
    b.harmonics_->push_back(k);
  return b;
}

HarmonicBasis HarmonicBasis::WeightedDiamond(const std::vector<int>& weights, int order) {
  const int d = static_cast<int>(weights.size());
  CheckArguments(d, order);
  for (int w : weights)
    if (w < 1) throw std::invalid_argument("HarmonicBasis: diamond weights must be >= 1");
  HarmonicBasis b(d, order, "weighted diamond");
  b.harmonics_->push_back(std::vector<int>(d, 0));
  for (auto& k : Enumerate(d, order, [&](const std::vector<int>& v) {
         long s = 0;
         for (int i = 0; i < d; ++i) s += long(weights[i]) * std::abs(v[i]);
         return s <= order;
       }))
    b.harmonics_->push_back(k);
  return b;
}

HarmonicBasis HarmonicBasis::FromHarmonics(int num_bases, std::vector<std::vector<int>> harmonics,
                                          int order, std::string shape) {
  CheckArguments(num_bases, std::max(order, 1));
  HarmonicBasis b(num_bases, order, std::move(shape));
  b.harmonics_->push_back(std::vector<int>(num_bases, 0));
  std::vector<std::vector<int>> kept;
  for (auto& k : harmonics) {
    if (static_cast<int>(k.size()) != num_bases)
      throw std::invalid_argument("HarmonicBasis: harmonic with " + std::to_string(k.size()) +
                                  " entries for " + std::to_string(num_bases) + " bases");
    if (!Canonical(k))
      for (int& v : k) v = -v;
    if (Canonical(k)) kept.push_back(std::move(k));  // zero is never canonical
  }
  // Same order as the standard shapes (total degree, then lexicographic), so
  // that low harmonics come first whatever order the caller listed them in.
  auto l1 = [](const std::vector<int>& v) {
    int s = 0;
    for (int x : v) s += std::abs(x);
    return s;
  };
  std::sort(kept.begin(), kept.end(), [&](const auto& a, const auto& c) {
    return l1(a) != l1(c) ? l1(a) < l1(c) : a < c;
  });
  kept.erase(std::unique(kept.begin(), kept.end()), kept.end());
  for (auto& k : kept) b.harmonics_->push_back(std::move(k));
  return b;
}

int HarmonicBasis::Reach(int base) const {
  int r = 0;
  for (const auto& k : *harmonics_) r = std::max(r, std::abs(k[base]));
  return r;
}

int HarmonicBasis::Find(const std::vector<int>& k) const {
  std::vector<int> neg(k);
  for (int& v : neg) v = -v;
  for (int i = 0; i < size(); ++i)
    if ((*harmonics_)[i] == k || (*harmonics_)[i] == neg) return i;
  return -1;
}

double HarmonicBasis::Frequency(int k, const std::vector<double>& w) const {
  double f = 0;
  for (int i = 0; i < num_bases_; ++i) f += (*harmonics_)[k][i] * w[i];
  return f;
}

}  // namespace rmhb
