#include <gtest/gtest.h>
#include <iostream>
#include "rmhb/model/recast.h"

using namespace rmhb::model;

TEST(Smoke, Pendulum) {
  const char* text = R"yaml(
name: pendulum
variables: [theta]
parameters: {theta0: 1.5}
equations:
  - "theta'' + sin(theta) = 0"
frequencies:
  - {guess: 0.86}
conditions:
  - "theta(0) = theta0"
  - "theta'(0) = 0"
initial_state: {theta: theta0, "theta'": 0}
guess: {theta: "theta0*cos(w*t)"}
)yaml";
  ModelDefinition m = ParseModel(text, "pendulum.yaml");
  RecastResult r = Recast(m);
  std::cout << r.Report();
}

#include "rmhb/harmonic_balance.h"
TEST(Smoke, PendulumSolve) {
  const char* text = R"yaml(
name: pendulum
variables: [theta]
parameters: {theta0: 1.5}
equations:
  - "theta'' + sin(theta) = 0"
frequencies:
  - {guess: 0.86}
conditions:
  - "theta(0) = theta0"
  - "theta'(0) = 0"
guess: {theta: "theta0*cos(w*t)"}
)yaml";
  ModelDefinition m = ParseModel(text, "pendulum.yaml");
  RecastResult r = Recast(m);
  rmhb::HarmonicBalanceOptions o;
  o.order = 25;
  auto s = rmhb::SolveHarmonicBalance(r.problem, r.InitialGuess(o.order), o);
  std::cout << s.FullReport();
  std::printf("w = %.17g err %.3e\n", s.solution->frequencies()[0], s.solution->frequencies()[0]-0.860608346679612985103549304862);
}
