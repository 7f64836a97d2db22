#include "rmhb/pipeline/reference.h"

#include <algorithm>
#include <cmath>

namespace rmhb {

ReferenceErrors ErrorsAgainst(const ExactReference& ref, const HarmonicSolution& sol) {
  ReferenceErrors e;
  if (ref.has_frequency()) e.frequency = sol.frequencies()[0] - ref.frequency;
  if (ref.has_amplitude()) {
    const int j = sol.IndexOf(ref.amplitude_variable);
    if (j >= 0) e.amplitude = sol.Amplitude(j) - ref.amplitude;
  }
  if (ref.solution && ref.has_frequency()) {
    const double T = 2 * M_PI / ref.frequency;
    double worst = 0;
    for (int i = 0; i <= 2000; ++i) {
      const double t = T * i / 2000;
      worst = std::max(worst, std::abs(sol.Value(0, t) - ref.solution(t)));
    }
    e.max_error = worst;
  }
  return e;
}

}  // namespace rmhb
