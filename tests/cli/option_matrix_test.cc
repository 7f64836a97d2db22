// Every option of every command, alone and with each option that asks for
// an output: the command either works or refuses (exit 1, 2, 3, 5 or 6 with a
// message); an exit 0 that did not write what was asked for (a plot, a
// CSV, a result file, a log, JSON on stdout, a validation or stability
// report) is a silent no-op and fails the test. The options come from each
// command's --help, so a new option without a sample value here fails too.
// The README's usage lines are checked against the same --help lists.

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "tests/cli/cli_run.h"

namespace rmhb::testing {
namespace {

namespace fs = std::filesystem;

// The options a command's --help lists (long names), with the aliases of each.
std::vector<std::vector<std::string>> HelpOptions(const std::string& command) {
  const CliRun help = Capture(std::string(RMHB_CLI) + " " + command + " --help");
  std::vector<std::vector<std::string>> options;
  std::istringstream in(help.out);
  const std::regex option(R"(^  ((?:-[A-Za-z],)?--[a-z][a-z-]*(?:,-?-?[A-Za-z][a-z-]*)*)\b)");
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (!std::regex_search(line, m, option)) continue;
    std::vector<std::string> names;
    std::stringstream list(m[1]);
    for (std::string name; std::getline(list, name, ',');)
      if (name.rfind("--", 0) == 0) names.push_back(name);
    if (!names.empty() && names[0] != "--help") options.push_back(names);
  }
  return options;
}

// A value for each option ("" for a flag); {dir} is the run's own folder.
const std::map<std::string, std::string>& Samples() {
  static const std::map<std::string, std::string> samples = {
      {"--set", "F=0.8"}, {"--order", "20"}, {"--frequencies", "1.5"}, {"--sampling", "gcd"}, {"--basis", "box"},
      {"--samples", "64"}, {"--method", "hdhb"}, {"--solver", "lm"}, {"--scaling", "none"},
      {"--max-iterations", "50"}, {"--allow-aliasing", ""}, {"--residual-tol", "1e-12"}, {"--tol", "1e-8"}, {"--tol-quantity", "frequency"},
      {"--max-jacobian-gib", "2"}, {"--max-order", "64"}, {"--equations", "auto"}, {"--eval", "0:0.5:2"}, {"--csv", "{dir}/out.csv"},
      {"--validate", ""}, {"--stability", ""}, {"--validate-periods", "2"}, {"--plot", "{dir}/plot.png"},
      {"--json", ""}, {"--quiet", ""}, {"--continue", "w=1:1.2"}, {"--steps", "5"}, {"--max-step", "0.1"},
      {"--natural", ""}, {"--plot-var", "x"}, {"--no-stability", ""}, {"--stability-method", "monodromy"},
      {"--switch-branches", ""}, {"--torus-tail", "1e-5"}, {"--no-locking", ""}, {"--t-end", "80"},
      {"--transient", "20"}, {"--linear-solver", "sparse"},
      {"--samples-per-period", "32"}, {"--window", "2"}, {"--signal", "{signal}"}, {"--dt", "0.05"},
      {"--rtol", "1e-10"}, {"--atol", "1e-12"}, {"--integrator", "bdf"}, {"--orders", "5,6"},
      {"--methods", "rhb"}, {"--conditions", "model"}, {"--taylor", "7"}, {"--original-samples", "64"},
      {"--repeat", "2"}, {"--max-seconds", "10"}, {"--starts", "20"}, {"--range", "-1:1"}, {"--seed", "3"},
      {"--threads", "1"}, {"--reference-order", "24"}, {"--match-tolerance", "0.1"}, {"--no-floquet", ""},
      {"--grid", "F=0.5:1:2"}, {"--out", "{dir}/sweep.h5"}, {"--resume", ""}, {"--keep-journal", ""},
      {"--log", "{dir}/sweep.log"}, {"--plot-value", "count"}, {"--start", "guess"}, {"--validate-tol", "1e-6"},
  };
  return samples;
}

// Options that ask for an output, and how to see it after an exit 0.
struct Output {
  std::string file;     // a file that must exist (under {dir})
  std::string in_text;  // or a word the output must contain
};
const std::map<std::string, Output>& Outputs() {
  static const std::map<std::string, Output> outputs = {
      {"--plot", {"plot.png", ""}},      {"--csv", {"out.csv", ""}},  {"--out", {"sweep.h5", ""}},
      {"--log", {"sweep.log", ""}},      {"--json", {"", "{"}},       {"--validate", {"", "validat"}},
      {"--stability", {"", "stability"}}, {"--keep-journal", {"sweep.h5.journal", ""}},
  };
  return outputs;
}

struct Command {
  std::string help;  // the subcommand whose --help lists the options
  std::string base;  // a quick run of it
};

std::string Replace(std::string text, const std::string& key, const std::string& value) {
  for (size_t at; (at = text.find(key)) != std::string::npos;) text.replace(at, key.size(), value);
  return text;
}

// Runs base + the options (each with its sample value) in a folder of its
// own; the failure message when it exits 0 without an asked-for output, or
// exits with anything but 0, 1, 2, 3 or 5.
std::string Check(const Command& c, const std::vector<std::string>& options, const std::string& signal, int id,
                  int* code) {
  const fs::path dir = fs::temp_directory_path() / ("rmhb-options-" + std::to_string(::getpid()) + "-" + std::to_string(id));
  fs::create_directories(dir);
  std::string args = Replace(c.base, "{dir}", dir.string());
  for (const std::string& o : options)
    args += " " + o + (Samples().at(o).empty() ? "" : " " + Replace(Replace(Samples().at(o), "{dir}", dir.string()),
                                                                   "{signal}", signal));
  const CliRun run = Cli(args);
  *code = run.code;
  std::string failure;
  if (run.code != 0 && run.code != 1 && run.code != 2 && run.code != 3 && run.code != 5 && run.code != 6)
    failure = "exit " + std::to_string(run.code);
  if (run.code == 0)
    for (const std::string& o : options) {
      const auto out = Outputs().find(o);
      if (out == Outputs().end()) continue;
      if (!out->second.file.empty() && !fs::exists(dir / out->second.file))
        failure += o + " wrote no " + out->second.file + "; ";
      if (!out->second.in_text.empty() && run.out.find(out->second.in_text) == std::string::npos)
        failure += o + " printed no '" + out->second.in_text + "'; ";
    }
  fs::remove_all(dir);
  return failure.empty() ? "" : "rmhb " + args + "\n  " + failure + "\n" + run.out.substr(0, 400);
}

// Every option alone, and each output option with every other option.
void Walk(const Command& c) {
  static const std::string signal = [] {
    const std::string file = (fs::temp_directory_path() / ("rmhb-options-signal-" + std::to_string(::getpid()) + ".csv")).string();
    Cli("simulate duffing --t-end 200 --dt 0.1 --csv " + file);
    return file;
  }();
  std::vector<std::string> names;
  for (const auto& aliases : HelpOptions(c.help)) {
    const std::string& name = aliases[0];
    if (c.base.find(" " + name + " ") != std::string::npos || c.base.find(" " + name + "=") != std::string::npos)
      continue;  // part of the base run
    ASSERT_TRUE(Samples().count(name)) << c.help << ": no sample value for " << name << " in this test";
    names.push_back(name);
  }
  std::vector<std::vector<std::string>> runs;
  for (const std::string& a : names) {
    runs.push_back({a});
    if (Outputs().count(a))
      for (const std::string& b : names)
        if (b != a) runs.push_back({a, b});
  }
  std::atomic<size_t> next{0};
  std::mutex mutex;
  std::vector<std::string> failures;
  std::atomic<int> worked{0};
  auto worker = [&] {
    for (size_t i; (i = next++) < runs.size();) {
      int code = 0;
      const std::string failure = Check(c, runs[i], signal, static_cast<int>(i), &code);
      worked += code == 0;
      if (failure.empty()) continue;
      std::lock_guard<std::mutex> lock(mutex);
      failures.push_back(failure);
    }
  };
  std::thread t1(worker), t2(worker);
  t1.join();
  t2.join();
  for (const std::string& f : failures) ADD_FAILURE() << f;
  // Most combinations are meant to work: a base run that fails would make
  // every check above vacuous.
  EXPECT_GE(worked * 2, static_cast<int>(runs.size())) << c.base << ": only " << worked << " of " << runs.size()
                                                        << " runs exit 0";
  ::testing::Test::RecordProperty("runs", static_cast<int>(runs.size()));
}

TEST(OptionMatrix, Solve) { Walk({"solve", "solve duffing --order 6"}); }
TEST(OptionMatrix, Continuation) { Walk({"solve", "solve duffing --order 6 --continue w=1:1.3 --steps 4"}); }
TEST(OptionMatrix, Recast) { Walk({"recast", "recast duffing"}); }
TEST(OptionMatrix, Analyze) { Walk({"analyze", "analyze duffing --order 18 --transient 400"}); }
TEST(OptionMatrix, Identify) { Walk({"identify", "identify duffing --transient 400"}); }
TEST(OptionMatrix, Simulate) { Walk({"simulate", "simulate duffing --t-end 5"}); }
TEST(OptionMatrix, Convergence) { Walk({"convergence", "convergence duffing --orders 5 --methods rhb"}); }
TEST(OptionMatrix, MonteCarlo) { Walk({"montecarlo", "montecarlo duffing --starts 20 --order 3 --no-floquet"}); }
TEST(OptionMatrix, Sweep) { Walk({"sweep", "sweep duffing --grid w=1:1.2:2 --order 5 --starts 1 --out {dir}/sweep.h5"}); }
TEST(OptionMatrix, List) { Walk({"list", "list"}); }

// The README's usage blocks ("build/rmhb COMMAND ... [--option ...]") and its
// summary of who takes --json and --plot name only options the commands have.
TEST(OptionMatrix, ReadmeClaimsMatchTheCommands) {
  std::ifstream in(RMHB_SOURCE_DIR "/README.md");
  ASSERT_TRUE(in) << "README.md";
  std::map<std::string, std::set<std::string>> accepted;
  for (const char* c : {"solve", "recast", "analyze", "identify", "simulate", "convergence", "montecarlo", "sweep", "list"})
    for (const auto& aliases : HelpOptions(c))
      for (const auto& name : aliases) accepted[c].insert(name);
  std::string command;  // of the usage block being read
  int claims = 0;
  bool in_code = false;
  const std::regex usage(R"(^(?:\$ )?build/rmhb ([a-z]+)\b)"), option(R"(--[a-z][a-z-]*)");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("```", 0) == 0) {
      in_code = !in_code;
      command.clear();
      continue;
    }
    if (!in_code) continue;
    std::smatch m;
    if (std::regex_search(line, m, usage)) command = accepted.count(m[1]) ? std::string(m[1]) : "";
    else if (line.rfind("      ", 0) != 0) command.clear();  // a usage line continues indented
    if (command.empty() || line.find("(+ ") != std::string::npos) continue;
    for (auto it = std::sregex_iterator(line.begin(), line.end(), option); it != std::sregex_iterator(); ++it) {
      ++claims;
      EXPECT_TRUE(accepted[command].count(it->str())) << "README: `rmhb " << command << "` has no " << it->str()
                                                       << "\n  " << line;
    }
  }
  EXPECT_GT(claims, 50);
  for (const auto& [c, names] : accepted) EXPECT_TRUE(names.count("--json")) << c << " has no --json";
  for (const char* c : {"solve", "convergence", "identify", "simulate", "analyze", "sweep"})
    EXPECT_TRUE(accepted[c].count("--plot")) << c << " has no --plot";
}

}  // namespace
}  // namespace rmhb::testing
