#include "rmhb/sampling.h"

#include <cmath>
#include <numeric>
#include <stdexcept>

namespace rmhb {

const char* ToString(SamplingRule rule) {
  switch (rule) {
    case SamplingRule::kRhb: return "rhb";
    case SamplingRule::kHdhb: return "hdhb";
    case SamplingRule::kAft: return "aft";
  }
  return "?";
}

SamplingRule ParseSamplingRule(const std::string& name) {
  if (name == "rhb") return SamplingRule::kRhb;
  if (name == "hdhb") return SamplingRule::kHdhb;
  if (name == "aft") return SamplingRule::kAft;
  throw std::invalid_argument("unknown method '" + name + "' (expected rhb, hdhb or aft)");
}

long Sampling::total() const {
  long t = 1;
  for (int m : grid) t *= m;
  return t;
}

Sampling Sampling::Uniform(int samples) {
  if (samples < 1) throw std::invalid_argument("Sampling: need at least one sample");
  return {{samples}, {{1}}, "uniform, " + std::to_string(samples) + " samples", {}};
}

Sampling Sampling::Torus(const std::vector<int>& samples) {
  Sampling s;
  s.grid = samples;
  s.embedding.assign(samples.size(), std::vector<int>(samples.size(), 0));
  s.description = "torus grid";
  for (size_t g = 0; g < samples.size(); ++g) {
    if (samples[g] < 1) throw std::invalid_argument("Sampling: need at least one sample");
    s.embedding[g][g] = 1;
    s.description += (g ? " x " : " ") + std::to_string(samples[g]);
  }
  return s;
}

Sampling Sampling::Gcd(int samples, const std::vector<int>& ratios) {
  if (samples < 1) throw std::invalid_argument("Sampling: need at least one sample");
  return {{samples}, {ratios}, "GCD rule, " + std::to_string(samples) + " samples", {}};
}

std::vector<int> RationalRatios(const std::vector<double>& w, double tolerance, long max_ratio) {
  if (w.empty()) throw std::invalid_argument("RationalRatios: no frequencies");
  // Continued fraction of each w_i / w_0 until it is within tolerance; the
  // common denominator then gives integer ratios r_i.
  std::vector<long> num(w.size()), den(w.size());
  for (size_t i = 0; i < w.size(); ++i) {
    const double x = w[i] / w[0];
    long h0 = 1, h1 = 0, k0 = 0, k1 = 1;  // convergents h/k
    double r = x;
    bool found = false;
    for (int it = 0; it < 64; ++it) {
      const double a = std::floor(r);
      const long h = static_cast<long>(a) * h0 + h1, k = static_cast<long>(a) * k0 + k1;
      h1 = h0; h0 = h; k1 = k0; k0 = k;
      if (k > max_ratio || h > max_ratio) break;
      if (std::abs(double(h) / double(k) - x) <= tolerance * x) {
        found = true;
        break;
      }
      if (r - a < 1e-300) break;
      r = 1.0 / (r - a);
    }
    if (!found)
      throw std::invalid_argument(
          "GCD rule: frequency ratio " + std::to_string(x) + " has no rational approximation "
          "with terms up to " + std::to_string(max_ratio) + " within relative tolerance " +
          std::to_string(tolerance) + "; use the torus grid");
    num[i] = h0;
    den[i] = k0;
  }
  long common = 1;
  for (long d : den) common = common / std::gcd(common, d) * d;
  std::vector<int> ratios(w.size());
  long g = 0;
  for (size_t i = 0; i < w.size(); ++i) {
    const long r = num[i] * (common / den[i]);
    if (r > max_ratio) throw std::invalid_argument("GCD rule: ratios exceed " + std::to_string(max_ratio) + "; use the torus grid");
    ratios[i] = static_cast<int>(r);
    g = std::gcd(g, r);
  }
  for (int& r : ratios) r = static_cast<int>(r / g);
  return ratios;
}

int FftFriendlySize(int m) {
  for (int n = std::max(m, 1);; ++n) {
    int r = n;
    for (int p : {2, 3, 5, 7})
      while (r % p == 0) r /= p;
    if (r == 1) return n;
  }
}

int NonSmoothSamples(int reach, int oversampling, int alias_free) {
  int n = 1;
  while (n < oversampling * reach + 1 || n < alias_free) n *= 2;
  return n;
}

std::vector<int> SamplesForRule(const PolynomialSystem& system, const HarmonicBasis& basis,
                                SamplingRule rule, std::vector<int>* alias_free) {
  std::vector<int> out, minimum;
  const int phi = std::max(system.Degree(), 1);
  const bool pointwise = system.HasPointwise();
  for (int b = 0; b < basis.num_bases(); ++b) {
    const int reach = basis.Reach(b);
    if (system.HasNonSmooth() && rule != SamplingRule::kHdhb) {
      minimum.push_back(0);
      out.push_back(NonSmoothSamples(reach, kNonSmoothOversampling, system.AliasFreeSamples(reach, b)));
      continue;
    }
    if (pointwise) {
      minimum.push_back(0);
      int n = 1;
      while (n < 4 * reach + 1) n *= 2;
      out.push_back(rule == SamplingRule::kHdhb ? 2 * reach + 1
                    : rule == SamplingRule::kAft ? n
                                                 : FftFriendlySize(kPointwiseOversampling * reach + 1));
      continue;
    }
    const int m = system.AliasFreeSamples(reach, b);
    minimum.push_back(m);
    switch (rule) {
      case SamplingRule::kRhb: out.push_back(FftFriendlySize(m)); break;
      case SamplingRule::kHdhb: out.push_back(2 * reach + 1); break;
      case SamplingRule::kAft: {
        int n = 1;
        while (n < 2 * phi * reach + 1) n *= 2;
        out.push_back(n);
        break;
      }
    }
  }
  if (alias_free) *alias_free = minimum;
  return out;
}

}  // namespace rmhb
