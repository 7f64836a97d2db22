#include "rmhb/cli/solve_stability.h"

#include <cmath>
#include <complex>
#include <optional>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "rmhb/cli/solve_setup.h"
#include "rmhb/pipeline/stability.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;
using Multipliers = std::vector<std::complex<double>>;

json Complex(const Multipliers& values) {
  json out = json::array();
  for (const auto& v : values) out.push_back({Number(v.real()), Number(v.imag())});
  return out;
}

}  // namespace

json StabilityJson(const ProblemSource& source, const HarmonicSolution& solution) {
  const StabilitySummary s = Stability(source, solution);
  json out = json::object();
  if (s.hill)
    out["hill"] = {{"verdict", ToString(s.hill_verdict)},
                   {"stable", s.hill->stable},
                   {"multipliers", Complex(s.hill->multipliers)},
                   {"exponents", Complex(s.hill->exponents)},
                   {"max_real_part", Number(s.hill->max_real_part)},
                   {"trivial", s.hill->trivial},
                   {"seconds", s.hill->seconds}};
  else
    out["hill"] = {{"note", s.hill_note}};
  if (s.floquet)
    out["floquet"] = {{"ok", s.floquet->ok},
                      {"verdict", ToString(s.floquet_verdict)},
                      {"stable", s.floquet->stable},
                      {"multipliers", Complex(s.floquet->multipliers)},
                      {"trivial", s.floquet->trivial},
                      {"closure_error", Number(s.floquet->closure_error)},
                      {"integrator", s.floquet_integrator},
                      {"seconds", s.floquet->seconds},
                      {"message", s.floquet->message}};
  else
    out["floquet"] = {{"note", s.floquet_note}};
  if (s.max_multiplier_difference) {
    out["max_multiplier_difference"] = Number(*s.max_multiplier_difference);
    out["agree"] = s.agree();
  }
  out["verdict"] = ToString(s.verdict);
  return out;
}

void PrintStability(const json& s) {
  auto line = [](const char* name, const json& part) {
    if (part.contains("note")) {
      std::printf("stability    %s: %s\n", name, part["note"].get<std::string>().c_str());
      return;
    }
    if (part.contains("ok") && !part["ok"].get<bool>()) {
      std::printf("stability    %s: integration failed: %s\n", name, part["message"].get<std::string>().c_str());
      return;
    }
    std::printf("stability    %-8s %-8s multipliers", name, part["verdict"].get<std::string>().c_str());
    for (const auto& m : part["multipliers"]) {
      const double re = m[0].is_null() ? NAN : m[0].get<double>();
      const double im = m[1].is_null() ? NAN : m[1].get<double>();
      std::printf(" %.10g%+.10gi (|%.6g|)", re, im, std::hypot(re, im));
    }
    std::printf("\n");
  };
  line("Hill", s["hill"]);
  line("CVODE", s["floquet"]);
  if (s.contains("max_multiplier_difference") && !s["max_multiplier_difference"].is_null())
    std::printf("stability    the two agree to %.3e (max |mu_Hill - mu_CVODE|), verdicts %s\n",
                s["max_multiplier_difference"].get<double>(), s["agree"].get<bool>() ? "agree" : "DISAGREE");
  std::printf("stability    %s\n", s["verdict"].get<std::string>().c_str());
}

}  // namespace rmhb::cli
