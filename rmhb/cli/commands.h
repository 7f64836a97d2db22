#ifndef RMHB_CLI_COMMANDS_H_
#define RMHB_CLI_COMMANDS_H_

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "rmhb/cli/solve_setup.h"

namespace CLI {
class App;
}

namespace rmhb::cli {

struct SolveArgs {
  ModelSettings settings;
  bool validate = false;
  bool stability = false;   // Floquet multipliers by Hill's method and CVODE
  int validate_periods = 1;
  double validate_tol = 1e-8;  // relative to max|state|: above it the validation EXCEEDS (exit 6)
  bool json = false;
  bool quiet = false;
  std::string eval;         // "t0:dt:t1"
  std::string csv;          // file for --eval
  std::string plot;         // FILE.png|svg: response, error, phase portrait
  std::string start = "auto";  // auto: the guess, then a simulated/identified start; guess: the guess only
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


}  // namespace rmhb::cli

#endif  // RMHB_CLI_COMMANDS_H_
