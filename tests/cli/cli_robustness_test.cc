// Robustness of the command line: 200 randomly mangled argument lists (8
// shards of 25, fixed seeds; RMHB_CLI_FUZZ_PER_SHARD runs more) are given to
// the built `rmhb`. Each run must end by itself within its time limit with a
// documented exit code 0-6 and a message, never by a signal; a run that
// succeeds must not print "nan" or "inf" as a result, and --json output must
// be a JSON document. The mangled lists start from quick commands (tiny
// orders) so that every run takes milliseconds.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

struct CliRun {
  int code = -1;    // exit code; -1 when killed or crashed
  int signal = 0;   // the signal that ended it, if any
  bool timed_out = false;
  std::string out;  // stdout
  std::string err;  // stderr
};

// Reads a pipe into `text` until EOF; false once the deadline passed.
bool Drain(int fd, std::string* text, std::chrono::steady_clock::time_point deadline) {
  char buffer[4096];
  while (true) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                          deadline - std::chrono::steady_clock::now())
                          .count();
    if (left <= 0) return false;
    pollfd p{fd, POLLIN, 0};
    if (poll(&p, 1, static_cast<int>(left)) <= 0) continue;
    const ssize_t n = read(fd, buffer, sizeof buffer);
    if (n <= 0) return true;
    if (text->size() < (1u << 22)) text->append(buffer, static_cast<std::size_t>(n));
  }
}

// Runs the CLI with exactly these arguments (no shell), stdout and stderr
// captured separately, killed after `seconds`.
CliRun RunCli(const std::vector<std::string>& args, double seconds) {
  int out_pipe[2], err_pipe[2];
  if (pipe(out_pipe) != 0 || pipe(err_pipe) != 0) return {};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out_pipe[1], 1);
    dup2(err_pipe[1], 2);
    close(out_pipe[0]);
    close(err_pipe[0]);
    const int null = open("/dev/null", O_RDONLY);
    dup2(null, 0);
    std::vector<char*> argv{const_cast<char*>(RMHB_CLI)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(RMHB_CLI, argv.data());
    _exit(127);
  }
  close(out_pipe[1]);
  close(err_pipe[1]);
  CliRun run;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<long>(seconds * 1e3));
  // stderr is small (a message); read stdout first, then stderr.
  run.timed_out = !Drain(out_pipe[0], &run.out, deadline) || !Drain(err_pipe[0], &run.err, deadline);
  if (run.timed_out) kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  close(out_pipe[0]);
  close(err_pipe[0]);
  if (WIFEXITED(status)) run.code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) run.signal = WTERMSIG(status);
  return run;
}

std::vector<std::vector<std::string>> Templates(const std::string& scratch) {
  return {
      {"solve", "pendulum", "-N", "3"},
      {"solve", "pendulum", "-N", "4", "--json", "--validate"},
      {"solve", "duffing", "--order", "3", "--method", "hdhb", "--set", "w=1.2"},
      {"solve", "vanderpol", "-N", "4", "--solver", "lm", "--json"},
      {"solve", "examples/models/pendulum.yaml", "-N", "4", "--set", "theta0=1"},
      {"solve", "examples/models/softening-dae.yaml", "-N", "4", "--validate", "--json"},
      {"solve", "forced-vanderpol", "--p", "2", "--frequencies", "2.3,?0.99", "--json"},
      {"solve", "duffing", "-N", "3", "--eval", "0:0.5:2", "--csv", scratch + "/eval.csv"},
      {"recast", "examples/models/rayleigh-plesset.yaml", "--json"},
      {"identify", "--signal", scratch + "/missing.csv"},
      {"list", "--json"},
  };
}

const std::vector<std::string>& Pool() {
  static const std::vector<std::string> pool = {
      "-1", "0", "2", "3", "1e400", "-1e-3", "nan", "inf", "-inf", "abc", "", "--", "-N",
      "--order", "--samples", "-M", "5", "--set", "theta0=nan", "eps=-1", "w=0", "theta0=",
      "=1", "--frequencies", "?0", "1,2,3", "?nan", "2.3,?", "--validate", "--json", "--quiet",
      "--method", "aft", "hdhb", "--solver", "newton", "tikhonov", "--max-iterations", "1",
      "999999999", "99999999999999", "--allow-aliasing", "--eval", "0:1:2", "0:-1:2", "--csv",
      "/nonexistent/dir/x.csv", "--basis", "box", "--sampling", "gcd", "--residual-tol", "1e-300",
      "--t-end", "--transient", "--signal", "examples/models/pendulum.yaml", "vanderpol",
      "asym-pendulum", "x''", "\xff\xfe", "--help", "--version", "solve", "recast", "identify"};
  return pool;
}

std::vector<std::string> Mangle(std::vector<std::string> args, std::mt19937& rng) {
  const int edits = 1 + static_cast<int>(rng() % 3);
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = args.empty() ? 0 : rng() % args.size();
    const std::string& token = Pool()[rng() % Pool().size()];
    switch (rng() % 5) {
      case 0:  // replace
        if (!args.empty()) args[at] = token;
        break;
      case 1:  // insert
        args.insert(args.begin() + static_cast<long>(at), token);
        break;
      case 2:  // delete
        if (!args.empty()) args.erase(args.begin() + static_cast<long>(at));
        break;
      case 3:  // duplicate
        if (!args.empty()) args.insert(args.begin() + static_cast<long>(at), args[at]);
        break;
      default:  // swap
        if (args.size() > 1) std::swap(args[at], args[rng() % args.size()]);
    }
  }
  return args;
}

std::string Show(const std::vector<std::string>& args) {
  std::string s = "rmhb";
  for (const std::string& a : args) s += " '" + a + "'";
  return s;
}

class CliFuzz : public ::testing::TestWithParam<int> {};

// A printed number that is not finite, as C's printf and nlohmann::json
// would spell it: "nan" or "inf" in any case, not inside a word ("infinite").
// (Not std::regex: GCC 12 warns inside it under the sanitizers.)
bool MentionsNonFinite(const std::string& text) {
  auto letter = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; };
  std::string lower(text.size(), ' ');
  std::transform(text.begin(), text.end(), lower.begin(),
                 [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); });
  for (const char* word : {"nan", "inf"})
    for (size_t p = lower.find(word); p != std::string::npos; p = lower.find(word, p + 1))
      if ((p == 0 || !letter(lower[p - 1])) && (p + 3 == lower.size() || !letter(lower[p + 3]))) return true;
  return false;
}

TEST_P(CliFuzz, MangledArgumentsEndInADocumentedExitCode) {
  const char* count_env = std::getenv("RMHB_CLI_FUZZ_PER_SHARD");
  const int runs = count_env ? std::atoi(count_env) : 25;
  std::mt19937 rng(1000u + static_cast<unsigned>(GetParam()));
  const std::string scratch = ::testing::TempDir();
  const auto templates = Templates(scratch);
  int codes[7] = {0, 0, 0, 0, 0, 0, 0};  // one per documented exit code 0..6
  double slowest = 0;
  std::string slowest_args;
  for (int i = 0; i < runs; ++i) {
    const std::vector<std::string> args = Mangle(templates[rng() % templates.size()], rng);
    const auto start = std::chrono::steady_clock::now();
    const CliRun r = RunCli(args, 30.0);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > slowest) slowest = seconds, slowest_args = Show(args);
    SCOPED_TRACE(Show(args));
    ASSERT_FALSE(r.timed_out) << "hang";
    ASSERT_EQ(r.signal, 0) << "killed by signal " << r.signal << "\n" << r.err;
    ASSERT_GE(r.code, 0);
    ASSERT_LE(r.code, 6) << r.err;  // 5: non-physical, 6: validation above --validate-tol
    EXPECT_NE(r.code, 4) << "internal error: " << r.err;
    ++codes[r.code];
    if (r.code != 0) {
      EXPECT_FALSE(r.err.empty() && r.out.empty()) << "no message";
    }
    bool mentions_non_finite = false;
    for (const std::string& a : args) mentions_non_finite |= MentionsNonFinite(a);
    if (r.code == 0 && !mentions_non_finite) {
      EXPECT_FALSE(MentionsNonFinite(r.out)) << r.out;
    }
    const bool json = std::find(args.begin(), args.end(), "--json") != args.end();
    if (json && (r.code == 0 || r.code == 3 || r.code == 5) && !r.out.empty() && r.out[0] == '{') {
      EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
    }
  }
  std::printf("  shard %d: %d runs, exit codes 0:%d 1:%d 2:%d 3:%d 4:%d 5:%d 6:%d; slowest %.2f s: %s\n",
              GetParam(), runs, codes[0], codes[1], codes[2], codes[3], codes[4], codes[5], codes[6],
              slowest,
              slowest_args.c_str());
}

INSTANTIATE_TEST_SUITE_P(Shards, CliFuzz, ::testing::Range(0, 8));

// Each invalid value named, with exit code 2 (bad input) or 1 (usage).
TEST(CliOptions, InvalidValuesAreRejectedClearly) {
  struct Case {
    std::vector<std::string> args;
    int code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"solve", "pendulum", "--order", "-1"}, 2, "--order must be >= 1 (got -1)"},
      {{"solve", "pendulum", "--order", "0"}, 2, "--order must be >= 1 (got 0)"},
      {{"solve", "pendulum", "--samples", "-1"}, 2, "--samples must be >= 1 (got -1)"},
      {{"solve", "pendulum", "--residual-tol", "nan"}, 2, "--residual-tol must be finite and > 0"},
      {{"solve", "pendulum", "--residual-tol", "-1e-12"}, 2, "--residual-tol must be finite and > 0"},
      {{"solve", "pendulum", "--set", "theta0=inf"}, 2, "--set theta0: value must be finite"},
      {{"solve", "pendulum", "--set", "theta0=nan"}, 2, "--set theta0: value must be finite"},
      {{"solve", "examples/models/pendulum.yaml", "--set", "theta0=-inf"}, 2,
       "--set theta0: value must be finite"},
      {{"solve", "pendulum", "--frequencies", "?0"}, 2, "frequencies must be > 0"},
      {{"solve", "pendulum", "--frequencies", "nan"}, 2, "'nan' is not a finite number"},
      {{"solve", "duffing", "--set", "w=-2"}, 2, "w must be > 0"},
      {{"solve", "duffing", "--order", "5", "--samples", "12"}, 2, "samples below the alias-free bound (21)"},
      {{"identify", "pendulum", "--t-end", "-5"}, 1, "'-5' must be a finite number > 0"},
      {{"identify", "pendulum", "--transient", "nan"}, 1, "'nan' must be a finite number >= 0"},
      // An integration that stops is no internal error (it was exit 4).
      {{"identify", "tests/pipeline/models/coulomb-friction.yaml"}, 3, "the record's integration stopped"},
      {{"identify", "tests/pipeline/models/coulomb-friction.yaml", "--json"}, 3, "\"status\": \"integration_stopped\""},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(Show(c.args));
    const CliRun r = RunCli(c.args, 30.0);
    EXPECT_EQ(r.code, c.code) << r.err;
    EXPECT_NE((r.err + r.out).find(c.message), std::string::npos) << r.err << r.out;
  }
  // M below the alias bound is accepted when asked for.
  EXPECT_EQ(RunCli({"solve", "duffing", "--order", "5", "--samples", "12", "--allow-aliasing", "-q"},
                   30.0)
                .code,
            0);
}

// C = 0 leaves the Rayleigh-Plesset bubble without its equilibrium, and the
// example's starting guess gives non-finite residuals: exit 3, the residual
// reported as not finite (JSON null), never as 0, and nothing printed as a
// solution.
TEST(CliOptions, NonFiniteResidualsAreReportedNotPrinted) {
  const CliRun text = RunCli({"solve", "rayleigh-plesset", "--set", "C=0"}, 30.0);
  EXPECT_EQ(text.code, 3) << text.err;
  EXPECT_NE(text.err.find("non-finite residuals"), std::string::npos) << text.err;
  EXPECT_NE(text.err.find("max|F| = inf"), std::string::npos) << text.err;
  EXPECT_EQ(text.out.find("k=1:"), std::string::npos) << text.out;
  const CliRun json = RunCli({"solve", "rayleigh-plesset", "--set", "C=0", "--json"}, 30.0);
  EXPECT_EQ(json.code, 3);
  const nlohmann::json j = nlohmann::json::parse(json.out);
  EXPECT_EQ(j["status"], "failed");
  EXPECT_TRUE(j["residual"].is_null());
  EXPECT_FALSE(j.contains("coefficients"));
}

}  // namespace

namespace {

// A model with an algebraic equation is validated with IDA, not refused.
TEST(CliDae, ValidateIntegratesTheDaeWithIda) {
  const CliRun r = RunCli(
      {"solve", "examples/models/softening-dae.yaml", "--order", "60", "--validate", "--json"}, 60.0);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["validation"]["status"], "ok");
  EXPECT_NE(j["validation"]["integrator"].get<std::string>().find("IDA"), std::string::npos);
  // z = 1/(1 + x^2) has slowly decaying harmonics: 1.9e-7 at N = 30 is its
  // truncation; at N = 60 what is left is IDA's own error at rtol 1e-14,
  // which depends on the build's last bits: 4.6e-10 on one machine, 1.4e-9
  // on another (-march=native).
  EXPECT_LT(j["validation"]["max_error"].get<double>(), 3e-9);
}

}  // namespace
