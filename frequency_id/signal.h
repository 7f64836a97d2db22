#ifndef RMHB_FREQUENCY_ID_SIGNAL_H_
#define RMHB_FREQUENCY_ID_SIGNAL_H_

#include <string>
#include <vector>

#include <Eigen/Core>

namespace rmhb::frequency_id {

// A uniformly sampled multichannel record: sample n of channel c was taken at
// t = t0 + n * dt. Frequencies everywhere in this layer are angular
// (radians per unit of t).
struct Signal {
  double dt = 0.0;
  double t0 = 0.0;
  Eigen::MatrixXd samples;  // rows = time, cols = channels
  std::vector<std::string> channel_names;  // empty, or one name per column

  int num_samples() const { return static_cast<int>(samples.rows()); }
  int num_channels() const { return static_cast<int>(samples.cols()); }
  double duration() const { return dt * num_samples(); }
};

// Checks what every analysis here relies on: dt > 0 and finite, finite t0
// and samples, at least `min_samples` rows and one column, and names either
// absent or one per channel. On failure returns false and, if `why` is not
// null, says what is wrong.
bool ValidateSignal(const Signal& signal, int min_samples, std::string* why);

}  // namespace rmhb::frequency_id

#endif  // RMHB_FREQUENCY_ID_SIGNAL_H_
