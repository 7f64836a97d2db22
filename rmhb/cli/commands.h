#ifndef RMHB_CLI_COMMANDS_H_
#define RMHB_CLI_COMMANDS_H_

#include <map>
#include <string>
#include <utility>
#include <vector>

namespace CLI {
class App;
}

namespace rmhb::cli {

struct SolveArgs {
  std::string model;
  std::vector<std::string> set;  // name=value
  int order = -1;                // -1: the example's default
  int samples = -1;              // -1: by the method's rule
  std::string method = "rhb";
  std::string solver = "auto";
  int max_iterations = 100;
  bool allow_aliasing = false;
  bool validate = false;
  int validate_periods = 1;
  bool json = false;
  bool quiet = false;
  std::string frequencies;  // "w1,w2"; "?w" marks an unknown with guess w
  std::string sampling = "torus";
  std::string shape = "diamond";
  bool shape_given = false;
  std::string eval;         // "t0:dt:t1"
  std::string csv;          // file for --eval
};

struct RecastArgs {
  std::string model;
  std::vector<std::string> set;
  bool json = false;
};

void AddSolveOptions(CLI::App* app, SolveArgs* args);
int RunSolve(const SolveArgs& args);
int RunList(bool json);
void AddRecastOptions(CLI::App* app, RecastArgs* args);
int RunRecast(const RecastArgs& args);

// "name=value" -> (name, value); throws std::invalid_argument saying which
// argument is malformed or not a finite number.
std::pair<std::string, double> ParseAssignment(const std::string& text);
// Every --set of a command, as parameter overrides.
std::map<std::string, double> ParseOverrides(const std::vector<std::string>& assignments);

}  // namespace rmhb::cli

#endif  // RMHB_CLI_COMMANDS_H_
