#include "rmhb/cli/commands.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>

#include "frequency_id/signal_io.h"
#include "frequency_id/spectrum.h"
#include "rmhb/cli/exit_codes.h"
#include "rmhb/model/model_error.h"
#include "rmhb/plot/figures.h"
#include "rmhb/plot/plot.h"
#include "examples/example_model.h"
#include "rmhb/pipeline/identify.h"
#include "rmhb/pipeline/settings.h"

namespace rmhb::cli {
namespace {

using nlohmann::json;

}  // namespace

void AddIdentifyOptions(CLI::App* app, IdentifyArgs* a) {
  app->add_option("model", a->model, "Example name or model file to integrate (or use --signal)");
  app->add_option("--signal", a->signal, "CSV file: a time column, then one column per channel");
  app->add_option("--set", a->set, "Override a model parameter: --set name=value (repeatable)");
  // Explicit values must be finite: the defaults are marked by 0 and -1.
  auto finite_at_least = [](double low, bool strict) {
    return CLI::Validator(
        [low, strict](std::string& text) -> std::string {
          char* end = nullptr;
          const double v = std::strtod(text.c_str(), &end);
          const bool ok = end != text.c_str() && *end == '\0' && std::isfinite(v) &&
                          (strict ? v > low : v >= low);
          return ok ? "" : "'" + text + "' must be a finite number " + (strict ? "> " : ">= ") + "0";
        },
        strict ? "POSITIVE" : "NONNEGATIVE");
  };
  app->add_option("--t-end", a->t_end, "Length of the integrated record (default: 300 periods of the slowest base, and at "
                  "least 20 beat periods of two close bases; with --signal: keep the first T time units)")
      ->check(finite_at_least(0, true));
  app->add_option("--transient", a->transient, "Initial time to discard (default: a tenth of --t-end; with --signal: none)")
      ->check(finite_at_least(0, false));
  app->add_option("--samples-per-period", a->samples_per_period,
                  "Samples per period of the fastest base (default 0: 32, up to 4 times denser while lines "
                  "above Nyquist would fold back into the record)")
      ->check(CLI::Range(0, 4096));
  app->add_option("--window", a->window, "Hann^q window order q (0: chosen from the line spacing)")
      ->check(CLI::Range(0, 8));
  app->add_option("--plot", a->plot, "Draw the spectrum with the labelled lines into FILE.png or FILE.svg");
  app->add_flag("--json", a->json, "Machine-readable output");
  app->footer("Exit codes: 0 ok, 1 usage, 2 bad input (unreadable CSV, unknown model, bad value,\n"
              "gnuplot missing for --plot), 3 no usable bases found (the message says why) or the\n"
              "record's integration stopped, 4 internal.");
}

int RunIdentify(const IdentifyArgs& a) {
  if (a.model.empty() == a.signal.empty())
    throw std::invalid_argument("identify needs either a model or --signal FILE.csv");
  if (!a.plot.empty()) plot::CheckPlotRequest(a.plot);
  IdentifyOptions options;
  options.t_end = a.t_end;
  options.transient = a.transient;
  options.samples_per_period = a.samples_per_period;
  options.window = a.window;
  IdentifySummary summary;
  if (!a.signal.empty()) {
    frequency_id::Signal signal;
    const frequency_id::CsvReadResult read = frequency_id::ReadSignalCsv(a.signal, &signal);
    if (!read.ok()) throw std::invalid_argument(read.message);
    summary = Identify(std::move(signal), options);
  } else {
    const Model model = examples::LoadModelOrExample(a.model, ParseOverrides(a.set));
    try {
      summary = Identify(model, options);
    } catch (const model::ModelError&) {
      throw;  // the model's own error: exit 2 with file:line:column, as everywhere
    } catch (const std::runtime_error& e) {
      // The model's record could not be integrated (a stick of sign()
      // friction, a blow-up): no record, no bases; not an internal error.
      const std::string why = std::string("the record's integration stopped: ") + e.what();
      if (a.json) std::cout << json{{"status", "integration_stopped"}, {"message", why}}.dump(1) << "\n";
      std::fprintf(stderr, "rmhb: identify: %s\n", why.c_str());
      return kExitNotConverged;
    }
  }
  json out = summary.ToJson();
  if (!a.plot.empty()) {
    plot::PlotSpectrum(summary.signal, summary.identification, a.plot);
    out["plot"] = a.plot;
  }
  if (a.json)
    std::cout << out.dump(1) << "\n";
  else
    std::printf("%s", summary.FullReport().c_str());
  return summary.usable() ? kExitOk : kExitNotConverged;
}

}  // namespace rmhb::cli
