// Robustness: a few hundred randomly mutated model texts (fixed seed) must
// each end in a ModelError or a valid model; nothing may crash, hang or throw
// anything else. Valid models are recast, validated and given a guess.

#include <chrono>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rmhb/model/recast.h"

namespace rmhb::model {
namespace {

std::vector<std::string> Seeds() {
  std::vector<std::string> seeds;
  for (const char* name : {"pendulum", "relativistic", "duffing", "vanderpol", "forced-vanderpol",
                           "rayleigh-plesset", "asym-pendulum", "softening-dae"}) {
    std::ifstream in(std::string(RMHB_SOURCE_DIR) + "/examples/models/" + name + ".yaml");
    std::ostringstream text;
    text << in.rdbuf();
    seeds.push_back(text.str());
  }
  seeds.push_back(
      "variables: [x]\nparameters: {A: 0.5, F: 0.1}\n"
      "equations: [\"x'' + x/sqrt(1 + x^2) + tan(x)/10 + atan(x) + exp(x) - 1 + log(2 + x) - log(2)"
      " + asin(x/2) + acos(x/2) - pi/2 + sinh(x) + tanh(x)*cosh(x) + x^0.3^2 = F*sin(2*w*t)\"]\n"
      "frequencies: [{guess: 1}]\nconditions: [\"x(0) = A\", \"x'(0) = 0\"]\n"
      "guess: {x: \"A*cos(w*t)\"}\n");
  return seeds;
}

std::string Mutate(std::string text, std::mt19937& rng) {
  static const std::vector<std::string> tokens = {
      "'",   "''",  "(",   ")",   "^",     "^99",   "^-3",  "1e999", "abs(", "sin(",  "x",
      "/0",  ":",   "-",   "[",   "]",     "{",     "}",    "\n",    "  ",   "#",     "*",
      "=",   "w",   "t",   "pi",  "nan",   ".inf",  "\"",   "&a ",   "*a",   "!!str ", "---",
      ",",   "0",   "1/",  "log(", "exp(", "x''''", "^(1/3)", "theta", "w2", "{guess: ", "- "};
  const int mutations = 1 + static_cast<int>(rng() % 3);
  for (int m = 0; m < mutations && !text.empty(); ++m) {
    const std::size_t at = rng() % text.size();
    switch (rng() % 5) {
      case 0: {  // byte flip
        const unsigned r = rng() % 10;
        text[at] = r == 0 ? static_cast<char>(rng() % 256) : static_cast<char>(32 + rng() % 95);
        break;
      }
      case 1:  // truncation
        text.resize(at);
        break;
      case 2:  // inserted token
        text.insert(at, tokens[rng() % tokens.size()]);
        break;
      case 3:  // deletion
        text.erase(at, 1 + rng() % 10);
        break;
      case 4: {  // duplicated line
        const std::size_t begin = text.rfind('\n', at) == std::string::npos ? 0 : text.rfind('\n', at) + 1;
        const std::size_t end = text.find('\n', at);
        const std::string line = text.substr(begin, end == std::string::npos ? std::string::npos : end - begin + 1);
        text.insert(begin, line);
        break;
      }
    }
  }
  return text;
}

TEST(ModelFuzz, MutatedModelsEndInAModelErrorOrAValidModel) {
  // RMHB_FUZZ_SEED / RMHB_FUZZ_PER_SEED run a longer campaign on demand.
  const char* seed_env = std::getenv("RMHB_FUZZ_SEED");
  const char* count_env = std::getenv("RMHB_FUZZ_PER_SEED");
  std::mt19937 rng(seed_env ? static_cast<unsigned>(std::atol(seed_env)) : 20240611u);
  const int per_seed = count_env ? std::atoi(count_env) : 50;
  const std::vector<std::string> seeds = Seeds();
  int parse_errors = 0, recast_errors = 0, guess_errors = 0, valid = 0;
  double slowest = 0;
  for (const std::string& seed : seeds) {
    for (int i = 0; i < per_seed; ++i) {
      const std::string text = Mutate(seed, rng);
      const auto start = std::chrono::steady_clock::now();
      int stage = 0;
      try {
        const ModelDefinition m = ParseModel(text, "fuzz.yaml");
        stage = 1;
        const RecastResult r = Recast(m);
        stage = 2;
        r.problem.Validate();  // the core accepts what the recast produces
        r.InitialGuess(3);
        ++valid;
      } catch (const ModelError& e) {
        (stage == 0 ? parse_errors : stage == 1 ? recast_errors : guess_errors)++;
        EXPECT_EQ(e.file(), "fuzz.yaml");
        EXPECT_FALSE(e.message().empty());
        EXPECT_EQ(std::string(e.what()).find("internal"), std::string::npos)
            << e.what() << "\n--- text:\n" << text;
      } catch (const std::exception& e) {
        ADD_FAILURE() << "not a ModelError: " << e.what() << "\n--- text:\n" << text;
      }
      slowest = std::max(slowest, std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                                start).count());
    }
  }
  std::printf("  %d mutants: %d parse errors, %d recast errors, %d guess errors, %d valid; "
              "slowest %.1f ms\n",
              static_cast<int>(seeds.size()) * per_seed, parse_errors, recast_errors, guess_errors,
              valid, slowest * 1e3);
  EXPECT_GT(valid, per_seed / 3);
  EXPECT_GT(parse_errors, per_seed * 2);
  EXPECT_LT(slowest, 2.0);
}

// Random well-formed expressions (nested functions, powers, quotients) in the
// equation x'' + f(x, x', t) = 0: every recast succeeds or throws a
// ModelError, and on success the auxiliaries' guesses satisfy their pinning
// conditions (the recast and its guess agree on every definition).
std::string RandomExpression(std::mt19937& rng, int depth) {
  static const std::vector<std::string> functions = {"sin", "cos", "tan", "exp", "log", "asin", "acos",
                                                     "atan", "sinh", "cosh", "tanh", "sqrt", "cbrt"};
  static const std::vector<std::string> leaves = {"x", "x'", "a", "2", "0.5", "x*x'", "cos(w*t)",
                                                  "sin(2*w*t)"};
  static const std::vector<std::string> exponents = {"2", "3", "-1", "(1/2)", "(3/2)", "0.3",
                                                     "(-2/3)", "x"};
  if (depth == 0 || rng() % 4 == 0) return leaves[rng() % leaves.size()];
  const std::string a = RandomExpression(rng, depth - 1);
  switch (rng() % 6) {
    case 0: return functions[rng() % functions.size()] + "(" + a + ")";
    case 1: return "(" + a + ")^" + exponents[rng() % exponents.size()];
    case 2: return "(" + a + ") / (2 + " + RandomExpression(rng, depth - 1) + ")";
    case 3: return a + " + " + RandomExpression(rng, depth - 1);
    case 4: return a + " * " + RandomExpression(rng, depth - 1);
    default: return "-" + a;
  }
}

TEST(ModelFuzz, RandomExpressionsRecastConsistently) {
  std::mt19937 rng(7);
  int recast = 0, errors = 0, checked = 0;
  for (int i = 0; i < 300; ++i) {
    const std::string f = RandomExpression(rng, 4);
    const std::string text = "variables: [x]\nparameters: {a: 0.7}\nequations: [\"x'' + x + (" + f +
                             ")/10 = 0\"]\nfrequencies: [" + (i % 2 ? "{guess: 1}" : "1.3") + "]\nguess: {x: \"0.1 + 0.3*cos(w*t)\"}\n";
    try {
      const RecastResult r = Recast(ParseModel(text, "fuzz.yaml"));
      ++recast;
      r.problem.Validate();
      const Eigen::VectorXd z = r.guess({0.0});
      if (!z.allFinite()) continue;
      // z' from a centred difference of the guess (pins may read derivatives).
      const double h = 1e-6;
      const Eigen::VectorXd dz = (r.guess({h}) - r.guess({-h})) / (2 * h);
      Eigen::VectorXd gz(z.size()), gdz(z.size());
      for (std::size_t c = r.num_user_conditions; c < r.problem.conditions.size(); ++c) {
        gz.setZero();
        gdz.setZero();
        const double residual = r.problem.conditions[c].function(z, dz, &gz, &gdz);
        if (!std::isfinite(residual)) continue;
        EXPECT_LE(std::abs(residual), 1e-6 * (1 + z.cwiseAbs().maxCoeff()))
            << r.problem.conditions[c].description << "\n" << f << "\n" << r.Report();
        ++checked;
      }
    } catch (const ModelError& e) {
      ++errors;
      if (std::getenv("RMHB_FUZZ_VERBOSE")) std::printf("    %s\n", e.what());
      EXPECT_EQ(std::string(e.what()).find("internal"), std::string::npos) << e.what() << "\n" << f;
    } catch (const std::exception& e) {
      ADD_FAILURE() << "not a ModelError: " << e.what() << "\n" << f;
    }
  }
  std::printf("  300 random equations: %d recast (%d pins checked), %d model errors\n", recast, checked,
              errors);
  EXPECT_GT(recast, 200);
}

}  // namespace
}  // namespace rmhb::model
