#include "frequency_id/signal.h"

#include <cmath>
#include <sstream>

namespace rmhb::frequency_id {

bool ValidateSignal(const Signal& signal, int min_samples, std::string* why) {
  auto fail = [why](const std::string& message) {
    if (why != nullptr) *why = message;
    return false;
  };
  if (!(std::isfinite(signal.dt) && signal.dt > 0.0)) {
    std::ostringstream os;
    os << "sampling step dt must be positive and finite (got " << signal.dt << ")";
    return fail(os.str());
  }
  if (!std::isfinite(signal.t0)) return fail("start time t0 is not finite");
  if (signal.num_channels() < 1) return fail("signal has no channels");
  if (signal.num_samples() < min_samples) {
    std::ostringstream os;
    os << "signal has " << signal.num_samples() << " samples, at least " << min_samples
       << " are needed";
    return fail(os.str());
  }
  if (!signal.channel_names.empty() &&
      static_cast<int>(signal.channel_names.size()) != signal.num_channels()) {
    std::ostringstream os;
    os << signal.channel_names.size() << " channel names for " << signal.num_channels()
       << " channels";
    return fail(os.str());
  }
  for (int c = 0; c < signal.num_channels(); ++c) {
    for (int n = 0; n < signal.num_samples(); ++n) {
      if (!std::isfinite(signal.samples(n, c))) {
        std::ostringstream os;
        os << "sample " << n << " of channel " << c << " is not finite";
        return fail(os.str());
      }
    }
  }
  return true;
}

}  // namespace rmhb::frequency_id
