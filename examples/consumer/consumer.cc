// A user's program against the installed package (find_package(rmhb),
// rmhb::rmhb): load the model file it ships, solve it and check the solution
// against an integration of the original equation (as `rmhb solve
// --validate`), then run the whole analysis (integrate, identify the
// frequency, seed, solve, validate) and compare the two frequencies.
//   consumer [model.yaml]

#include <cmath>
#include <cstdio>
#include <exception>

#include "rmhb/rmhb.h"

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : RMHB_CONSUMER_MODEL;
  try {
    const rmhb::Model model = rmhb::examples::LoadModelOrExample(path);
    rmhb::SolveSettings settings;  // what `rmhb solve --order 25` sets
    settings.order = 25;
    const rmhb::PreparedSolve prepared = rmhb::PrepareSolve(model, settings);
    rmhb::SolveOptions options;  // rmhb solve --validate --validate-periods 20
    options.harmonic_balance = prepared.options;
    options.validate = true;
    options.validate_periods = 20;
    const rmhb::SolveSummary solved = rmhb::SolveModel(prepared.model, prepared.guess, options);
    std::printf("rmhb %s, %s: %s\n", RMHB_VERSION_STRING, model.name.c_str(), solved.BriefReport().c_str());
    if (solved.status != rmhb::SolveStatus::kConverged) {
      std::printf("%s: %s\n", rmhb::ToString(solved.status), solved.message.c_str());
      return 3;
    }
    const double w = solved.solution().frequencies()[0];
    const rmhb::integrators::ValidationReport& check = solved.validation->report;
    std::printf("validation: max error %.2e over 20 periods against %s (%s)\n", check.max_error,
                check.integrator.c_str(), solved.validation->verdict.Describe().c_str());

    rmhb::AnalyzeOptions analyze;
    analyze.solve = prepared.options;
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
