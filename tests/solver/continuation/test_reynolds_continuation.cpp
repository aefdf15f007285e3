// The Reynolds continuation's policy, against a stand-in for the discrete problem: which Re it
// tries, with which method and start, how the increment grows and halves, and where a stall
// hands over to following the branch by arclength. No PETSc, no MPI.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <regex>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/log.h"
#include "solver/continuation/arclength.h"
#include "solver/continuation/reynolds_continuation.h"

namespace naris::continuation {
namespace {

using nonlinear::ArclengthConstraint;
using nonlinear::NonlinearOptions;
using nonlinear::NonlinearReport;
using ns::FlowField;

// A one-node "flow" whose velocity is its Reynolds number: a branch u(Re) = Re.
FlowField at(double re) {
  return FlowField{{Eigen::Vector3d(re, 0.0, 0.0)}, {re}};
}

struct Try {
  double reynolds;
  bool pseudo_time;
  bool arclength;
  double start;  // the initial field's velocity (NaN: from rest)
};

// Converges where `converges(re, pseudo)` says so, in `iterations` steps; a constrained
// (arclength) solve converges at its predictor's Re.
class FakeSolves final : public SteadySolves {
 public:
  std::function<bool(double re, bool pseudo)> converges = [](double, bool) { return true; };
  int iterations = 2;
  std::vector<Try> tries;
  std::vector<double> checkpoints, branch;
  std::vector<ContinuationState> states;  // what each checkpoint recorded
  bool gave_up = false;

  FlowField solve(double re, const NonlinearOptions& o, const FlowField* initial,
                  const ArclengthConstraint* c, NonlinearReport& report) override {
    const bool pseudo = o.pseudo_cfl > 0.0;
    tries.push_back({re, pseudo, c != nullptr, initial ? initial->velocity[0][0] : NAN});
    report.iterations = iterations;
    report.residuals = {1.0, 1e-9};
    if (c) {
      report.reynolds = c->origin_reynolds + c->step * c->tangent_reynolds;
      report.converged = true;
      return at(report.reynolds);
    }
    report.converged = converges(re, pseudo);
    if (!report.converged) report.residuals = {1.0, 0.9};
    return at(re);
  }
  double inner_product(const FlowField& a, const FlowField& b) override {
    return a.velocity[0].dot(b.velocity[0]);
  }
  void checkpoint(double re, const FlowField&, const ContinuationState& state) override {
    checkpoints.push_back(re);
    states.push_back(state);
  }
  void branch_point(double re, const FlowField&, int, double) override { branch.push_back(re); }
  void giving_up(const std::vector<ContinuationStep>&) override { gave_up = true; }
};

ContinuationSettings settings(double pseudo_cfl, double target = 610.0, int max_steps = 40) {
  ContinuationSettings s;
  s.target = target;
  s.start = 50.0;
  s.max_steps = max_steps;
  s.nonlinear.pseudo_cfl = pseudo_cfl;
  return s;
}

// Solves that converge up to Re `limit` only (and at `also`, where given).
FakeSolves converging_up_to(double limit, double also = -1.0) {
  FakeSolves solves;
  solves.converges = [limit, also](double re, bool) { return re <= limit || re == also; };
  return solves;
}

class QuietLog : public ::testing::Test {
 protected:
  void SetUp() override { set_verbosity(Verbosity::quiet); }
  void TearDown() override { set_verbosity(Verbosity::normal); }
};
using ReynoldsContinuationTest = QuietLog;

std::vector<double> reynolds_of(const std::vector<Try>& tries) {
  std::vector<double> re;
  for (const Try& t : tries) re.push_back(t.reynolds);
  return re;
}

TEST_F(ReynoldsContinuationTest, IncrementGrowsByHalfAfterEachEasyStep) {
  FakeSolves solves;
  ReynoldsContinuation c(settings(0.0), solves);
  c.run();
  // 50, then +75, +112.5, +168.75, and the target instead of 659.375.
  EXPECT_EQ(reynolds_of(solves.tries), (std::vector<double>{50, 125, 237.5, 406.25, 610}));
  EXPECT_EQ(solves.checkpoints, reynolds_of(solves.tries));
  EXPECT_DOUBLE_EQ(c.solution().velocity[0][0], 610.0);
  EXPECT_EQ(c.steps().size(), 5u);
}

TEST_F(ReynoldsContinuationTest, IncrementStaysAfterAStepThatTookAThirdOfItsBudget) {
  FakeSolves solves;
  solves.iterations = 17;  // max_iterations 50: not below 50/3
  ReynoldsContinuation c(settings(0.0, 200.0), solves);
  c.run();
  EXPECT_EQ(reynolds_of(solves.tries), (std::vector<double>{50, 100, 150, 200}));
}

TEST_F(ReynoldsContinuationTest, StepsBeforeTheTargetStopAtTheStepTolerance) {
  struct Tolerances final : public SteadySolves {
    std::vector<double> tolerance;
    FlowField solve(double re, const NonlinearOptions& o, const FlowField*,
                    const ArclengthConstraint*, NonlinearReport& r) override {
      tolerance.push_back(o.tolerance);
      r.converged = true;
      r.iterations = 1;
      return at(re);
    }
    double inner_product(const FlowField&, const FlowField&) override { return 0.0; }
    void checkpoint(double, const FlowField&, const ContinuationState&) override {}
    void branch_point(double, const FlowField&, int, double) override {}
    void giving_up(const std::vector<ContinuationStep>&) override {}
  } solves;
  ReynoldsContinuation c(settings(0.0, 100.0), solves);
  c.run();
  EXPECT_EQ(solves.tolerance, (std::vector<double>{1e-5, 1e-8}));
}

TEST_F(ReynoldsContinuationTest, FromRestPseudoTimeFirstThenNewtonThenHalved) {
  FakeSolves solves = converging_up_to(100.0);  // nothing converges above Re 100
  ReynoldsContinuation c(settings(5.0, 110.0, 8), solves);
  EXPECT_THROW(c.run(), Error);
  ASSERT_GE(solves.tries.size(), 5u);
  // Re 50 from rest with pseudo-time; Re 110 (50 + 75, capped) with pseudo-time first, the method
  // of the last step, then by Newton alone; then half the increment, 80, which converges.
  EXPECT_EQ(solves.tries[0].reynolds, 50.0);
  EXPECT_TRUE(solves.tries[0].pseudo_time);
  EXPECT_TRUE(std::isnan(solves.tries[0].start));
  EXPECT_EQ(solves.tries[1].reynolds, 110.0);
  EXPECT_TRUE(solves.tries[1].pseudo_time);
  EXPECT_EQ(solves.tries[2].reynolds, 110.0);
  EXPECT_FALSE(solves.tries[2].pseudo_time);
  EXPECT_EQ(solves.tries[3].reynolds, 80.0);
  EXPECT_TRUE(solves.tries[3].pseudo_time);
  EXPECT_TRUE(solves.gave_up);
}

TEST_F(ReynoldsContinuationTest, TheMethodThatTookTheLastStepGoesFirst) {
  FakeSolves solves;
  // Pseudo-time fails everywhere but at the first step; Newton converges everywhere.
  int calls = 0;
  solves.converges = [&calls](double, bool pseudo) { return ++calls == 1 || !pseudo; };
  ReynoldsContinuation c(settings(5.0, 300.0), solves);
  c.run();
  // 50 (pseudo), 125 (pseudo fails, Newton converges), then Newton first at 237.5 and 300.
  ASSERT_EQ(solves.tries.size(), 5u);
  EXPECT_TRUE(solves.tries[1].pseudo_time);
  EXPECT_FALSE(solves.tries[2].pseudo_time);
  EXPECT_EQ(solves.tries[3].reynolds, 237.5);
  EXPECT_FALSE(solves.tries[3].pseudo_time);
  EXPECT_FALSE(solves.tries[4].pseudo_time);
}

TEST_F(ReynoldsContinuationTest, SecantPredictorAfterTwoNewtonSteps) {
  FakeSolves solves;
  ReynoldsContinuation c(settings(0.0, 300.0), solves);
  c.run();
  // From rest; from the last field; then from u₁ + (u₁ − u₀)(1/Re − 1/Re₁)/(1/Re₁ − 1/Re₀).
  ASSERT_EQ(solves.tries.size(), 4u);
  EXPECT_TRUE(std::isnan(solves.tries[0].start));
  EXPECT_EQ(solves.tries[1].start, 50.0);
  const double t = (1 / 237.5 - 1 / 125.0) / (1 / 125.0 - 1 / 50.0);
  EXPECT_DOUBLE_EQ(solves.tries[2].start, 125.0 + t * (125.0 - 50.0));
}

TEST_F(ReynoldsContinuationTest, NoSecantAfterAPseudoTimeStep) {
  FakeSolves solves;
  ReynoldsContinuation c(settings(5.0, 300.0), solves);
  c.run();
  // Every step converges with pseudo-time: each starts from the last field itself.
  for (std::size_t k = 1; k < solves.tries.size(); ++k)
    EXPECT_EQ(solves.tries[k].start, solves.tries[k - 1].reynolds) << k;
}

TEST_F(ReynoldsContinuationTest, StallHandsOverToArclengthWhichReachesTheTarget) {
  // Continuation in Re cannot pass Re 300 (a turning point, say); the target itself converges
  // from the chord once the branch has passed it.
  FakeSolves solves = converging_up_to(300.0, 610.0);
  ReynoldsContinuation c(settings(0.0, 610.0, 100), solves);
  c.run();
  bool arclength = false;
  for (const auto& step : c.steps()) arclength = arclength || step.arclength;
  EXPECT_TRUE(arclength);
  EXPECT_FALSE(solves.gave_up);
  ASSERT_FALSE(solves.tries.empty());
  EXPECT_EQ(solves.tries.back().reynolds, 610.0);
  EXPECT_FALSE(solves.tries.back().arclength);
  EXPECT_DOUBLE_EQ(c.solution().velocity[0][0], 610.0);
  // The hand-over came once the increment had been halved below 1e-3 of the target: the last
  // try in Re failed just past what continuation in Re reaches, within twice that increment.
  std::size_t first = 0;
  while (!solves.tries[first].arclength) ++first;
  ASSERT_GT(first, 0u);
  EXPECT_GT(solves.tries[first - 1].reynolds, 300.0);
  EXPECT_LT(solves.tries[first - 1].reynolds, 300.0 + 2 * 0.61);
  EXPECT_EQ(solves.branch.back(), 610.0);
}

TEST_F(ReynoldsContinuationTest, CheckpointsRecordWhereTheContinuationGoesNext) {
  FakeSolves newton;
  ReynoldsContinuation c(settings(0.0, 300.0), newton);
  c.run();
  ASSERT_EQ(newton.states.size(), 4u);
  // After Re 50: the next increment 75, no earlier step; after 125: 112.5, the step at 50.
  EXPECT_EQ(newton.states[0].next_step, 75.0);
  EXPECT_EQ(newton.states[0].earlier_reynolds, 0.0);
  EXPECT_FALSE(newton.states[0].pseudo_time);
  EXPECT_EQ(newton.states[1].next_step, 112.5);
  EXPECT_EQ(newton.states[1].earlier_reynolds, 50.0);
  ASSERT_EQ(newton.states[1].earlier.velocity.size(), 1u);
  EXPECT_EQ(newton.states[1].earlier.velocity[0][0], 50.0);
  EXPECT_EQ(newton.states[1].arclength_step, 0.0);
  // With pseudo-time: marked, and no earlier step for a secant across it.
  FakeSolves pseudo;
  ReynoldsContinuation d(settings(5.0, 300.0), pseudo);
  d.run();
  ASSERT_FALSE(pseudo.states.empty());
  for (const auto& s : pseudo.states) {
    EXPECT_TRUE(s.pseudo_time);
    EXPECT_EQ(s.earlier_reynolds, 0.0);
  }
  // On the branch: the arclength increment and the branch's point before.
  FakeSolves branch = converging_up_to(300.0, 610.0);
  ReynoldsContinuation e(settings(0.0, 610.0, 100), branch);
  e.run();
  bool on_branch = false;
  for (const auto& s : branch.states)
    if (s.arclength_step > 0.0) {
      on_branch = true;
      EXPECT_EQ(s.next_step, s.arclength_step);
      EXPECT_GT(s.earlier_reynolds, 0.0);
      EXPECT_EQ(s.earlier.velocity[0][0], s.earlier_reynolds);  // the fake's u(Re) = Re
    }
  EXPECT_TRUE(on_branch);
}

TEST_F(ReynoldsContinuationTest, StallWithoutArclengthIsAnErrorNamingTheReReached) {
  FakeSolves solves = converging_up_to(300.0);
  ContinuationSettings s = settings(0.0, 610.0, 100);
  s.arclength_steps = 0;
  ReynoldsContinuation c(s, solves);
  try {
    c.run();
    FAIL() << "a stall must be an error";
  } catch (const Error& e) {
    // The last Re reached lies within the final increment (< 1e-3 of the target) below 300.
    std::smatch m;
    const std::string what = e.what();
    ASSERT_TRUE(std::regex_search(what, m, std::regex("stalled at Re ([0-9.]+)"))) << what;
    EXPECT_GT(std::stod(m[1]), 300.0 - 2 * 0.61) << what;
    EXPECT_LE(std::stod(m[1]), 300.0) << what;
  }
  EXPECT_TRUE(solves.gave_up);
}

TEST_F(ReynoldsContinuationTest, ResumeTakesThePathTheCheckpointRecorded) {
  FakeSolves solves;
  ReynoldsContinuation c(settings(5.0), solves);
  ContinuationState state;
  state.next_step = 100.0;
  state.pseudo_time = false;
  c.resume(at(200.0), 200.0, state);
  EXPECT_EQ(c.next_reynolds(), 300.0);
  c.run();
  EXPECT_EQ(solves.tries.front().reynolds, 300.0);
  EXPECT_FALSE(solves.tries.front().pseudo_time);  // Newton took the checkpoint's step
  EXPECT_EQ(solves.tries.front().start, 200.0);
}

TEST_F(ReynoldsContinuationTest, ResumeFromASolutionFileStepsAQuarterOfTheWay) {
  FakeSolves solves;
  ReynoldsContinuation c(settings(5.0), solves);
  c.resume(at(400.0), 400.0, {});
  EXPECT_EQ(c.next_reynolds(), 500.0);
}

TEST_F(ReynoldsContinuationTest, AProlongedFieldAtTheTargetStartsTheTargetsStep) {
  FakeSolves solves;
  ReynoldsContinuation c(settings(5.0), solves);
  c.resume(at(610.0), 610.0, {});
  c.run();
  ASSERT_EQ(solves.tries.size(), 1u);
  EXPECT_EQ(solves.tries[0].reynolds, 610.0);
  EXPECT_EQ(solves.tries[0].start, 610.0);
  EXPECT_FALSE(solves.tries[0].pseudo_time);
}

TEST(Arclength, SecantIsAUnitVectorInTheConstraintsMetric) {
  ArclengthConstraint c;
  const InnerProduct inner = [](const FlowField& a, const FlowField& b) {
    return a.velocity[0].dot(b.velocity[0]);
  };
  const double length = aim_along_secant(c, at(100.0), 100.0, at(110.0), 110.0, inner);
  EXPECT_NEAR(length, std::sqrt(100.0 + 100.0 / (110.0 * 110.0)), 1e-12);
  EXPECT_NEAR(
      inner(c.tangent, c.tangent) + c.tangent_reynolds * c.tangent_reynolds / (110.0 * 110.0), 1.0,
      1e-12);
  c.origin = at(110.0);
  c.origin_reynolds = 110.0;
  c.step = length;
  EXPECT_NEAR(arclength_predictor(c).velocity[0][0], 120.0, 1e-12);
  EXPECT_NEAR(110.0 + c.step * c.tangent_reynolds, 120.0, 1e-12);
}

}  // namespace
}  // namespace naris::continuation
