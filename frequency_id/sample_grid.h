#ifndef RMHB_FREQUENCY_ID_SAMPLE_GRID_H_
#define RMHB_FREQUENCY_ID_SAMPLE_GRID_H_

#include <algorithm>
#include <cmath>

namespace rmhb::frequency_id {

inline constexpr double kPi = 3.141592653589793238462643383279502884;

// The sampling instants t_n = t0 + n dt, n = 0 .. size-1.
//
// Internally every phase is measured from the centre of the record,
// tau_n = t_n - Center(): |omega tau| is then at most omega T / 2, which halves
// the rounding error of the phase argument, and the symmetric windows make
// the first moments of tau vanish, which decouples frequency from phase in the
// least-squares problems.
struct SampleGrid {
  double t0 = 0.0;
  double dt = 1.0;
  int size = 0;

  double Center() const { return t0 + 0.5 * (size - 1) * dt; }
  // n - (size-1)/2 is exact in double, so tau_n carries a single rounding.
  double Tau(int n) const { return (n - 0.5 * (size - 1)) * dt; }
  double Duration() const { return size * dt; }
  // Spacing of the DFT frequencies, 2 pi / (N dt): the natural unit
  // ("bin") for line separations and window main lobes.
  double BinWidth() const { return 2.0 * kPi / Duration(); }
  double Nyquist() const { return kPi / dt; }
};

// Calls visit(n, cos(omega tau_n), sin(omega tau_n)) for every sample, in
// order. The phasor is advanced by a complex rotation (4 multiplies instead of
// two libm calls) and re-anchored with exact cos/sin every kPhasorAnchorStride
// samples, so the rotation's rounding error cannot build up beyond a few
// dozen ulps.
inline constexpr int kPhasorAnchorStride = 32;

// Only samples begin .. end-1, anchored at begin.
template <typename Visitor>
void ForEachPhasorInRange(const SampleGrid& grid, double omega, int begin, int end,
                          Visitor&& visit) {
  const double step_cos = std::cos(omega * grid.dt);
  const double step_sin = std::sin(omega * grid.dt);
  for (int start = begin; start < end; start += kPhasorAnchorStride) {
    const double phase = omega * grid.Tau(start);
    double c = std::cos(phase);
    double s = std::sin(phase);
    const int stop = std::min(end, start + kPhasorAnchorStride);
    for (int n = start; n < stop; ++n) {
      visit(n, c, s);
      const double next_c = c * step_cos - s * step_sin;
      s = s * step_cos + c * step_sin;
      c = next_c;
    }
  }
}

template <typename Visitor>
void ForEachPhasor(const SampleGrid& grid, double omega, Visitor&& visit) {
  ForEachPhasorInRange(grid, omega, 0, grid.size, visit);
}

// The same for two frequencies at once: visit(n, c1, s1, c2, s2). Used to
// swap a line for its refined self in a single pass over the samples.
template <typename Visitor>
void ForEachPhasorPair(const SampleGrid& grid, double omega1, double omega2, Visitor&& visit) {
  const double step_cos1 = std::cos(omega1 * grid.dt);
  const double step_sin1 = std::sin(omega1 * grid.dt);
  const double step_cos2 = std::cos(omega2 * grid.dt);
  const double step_sin2 = std::sin(omega2 * grid.dt);
  for (int start = 0; start < grid.size; start += kPhasorAnchorStride) {
    const double tau = grid.Tau(start);
    double c1 = std::cos(omega1 * tau), s1 = std::sin(omega1 * tau);
    double c2 = std::cos(omega2 * tau), s2 = std::sin(omega2 * tau);
    const int end = std::min(grid.size, start + kPhasorAnchorStride);
    for (int n = start; n < end; ++n) {
      visit(n, c1, s1, c2, s2);
      const double next_c1 = c1 * step_cos1 - s1 * step_sin1;
      s1 = s1 * step_cos1 + c1 * step_sin1;
      c1 = next_c1;
      const double next_c2 = c2 * step_cos2 - s2 * step_sin2;
      s2 = s2 * step_cos2 + c2 * step_sin2;
      c2 = next_c2;
    }
  }
}

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_SAMPLE_GRID_H_
