// A user's program against the installed package (find_package(rmhb),
// rmhb::rmhb): load the model file it ships, solve it, check the solution
// against an integration of the original equation, then run the whole
// analysis (integrate, identify the frequency, seed, solve, validate) and
// compare the two frequencies.
//   consumer [model.yaml]

#include <cmath>
#include <cstdio>
#include <exception>

#include "rmhb/rmhb.h"

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : RMHB_CONSUMER_MODEL;
  try {
    const rmhb::Model model = rmhb::LoadModel(path);
    rmhb::HarmonicBalanceOptions options;
    options.order = 25;
    const rmhb::HarmonicBalanceSummary solved =
        rmhb::SolveHarmonicBalance(model.problem, rmhb::GuessAtOrder(model, options.order), options);
    std::printf("rmhb %s, %s: %s\n", RMHB_VERSION_STRING, model.name.c_str(), solved.BriefReport().c_str());
    if (!solved.usable()) return 3;
    const double w = solved.solution->frequencies()[0];
    const rmhb::integrators::ValidationReport check = rmhb::ValidateOriginal(model, *solved.solution, 20 * 2 * M_PI / w);
    std::printf("validation: max error %.2e over 20 periods against %s\n", check.max_error, check.integrator.c_str());

    rmhb::AnalyzeOptions analyze;
    analyze.solve = options;
    const rmhb::AnalyzeSummary analysis = rmhb::Analyze(model, analyze);
    std::printf("%s", analysis.FullReport().c_str());
    if (!analysis.ok()) return 3;
    const double difference = std::abs(analysis.solve->solution->frequencies()[0] - w);
    std::printf("solve and analyze agree: |w - w'| = %.1e, w = %.15f\n", difference, w);
    return check.max_error < 1e-8 && difference < 1e-12 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "consumer: %s\n", e.what());
    return 2;
  }
}
