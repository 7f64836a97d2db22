#ifndef RMHB_CLI_IDENTIFY_COMMAND_H_
#define RMHB_CLI_IDENTIFY_COMMAND_H_

// `rmhb identify`: base frequencies and labelled components, from a user's
// sampled signal (CSV) or from a model's trajectory (CVODE on the original
// equations, the transient discarded).

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace rmhb::cli {

struct IdentifyArgs {
  std::string model;
  std::string signal;  // CSV file: t, channel...
  std::vector<std::string> set;
  double t_end = 0;      // 0: chosen from the guessed frequencies
  double transient = -1; // -1: a tenth of the record
  int samples_per_period = 32;
  int window = 0;        // Hann^q order, 0 = automatic
  std::string plot;      // spectrum with labelled lines, FILE.png|svg
  bool json = false;
};

void AddIdentifyOptions(CLI::App* app, IdentifyArgs* args);
int RunIdentify(const IdentifyArgs& args);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_IDENTIFY_COMMAND_H_
