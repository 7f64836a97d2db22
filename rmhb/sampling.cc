#include "rmhb/sampling.h"

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
  return {{samples}, {{1}}, "uniform, " + std::to_string(samples) + " samples"};
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
  return {{samples}, {ratios}, "GCD rule, " + std::to_string(samples) + " samples"};
}

int FftFriendlySize(int m) {
  for (int n = std::max(m, 1);; ++n) {
    int r = n;
    for (int p : {2, 3, 5, 7})
      while (r % p == 0) r /= p;
    if (r == 1) return n;
  }
}

std::vector<int> SamplesForRule(const PolynomialSystem& system, const HarmonicBasis& basis,
                                SamplingRule rule, std::vector<int>* alias_free) {
  std::vector<int> out, minimum;
  const int phi = std::max(system.Degree(), 1);
  for (int b = 0; b < basis.num_bases(); ++b) {
    const int reach = basis.Reach(b);
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
