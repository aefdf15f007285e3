// The drag law, settling and slip correction against their closed forms (VERIFICATION.md §6),
// and tracers in analytic Hagen–Poiseuille flow: the radius kept, the residence time
// L / (2Ū(1 − r²/R²)).
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdio>

#include "solver/particles/tracker.h"
#include "tests/solver/particles/analytic_flows.h"

namespace naris::particles {
namespace {

TEST(Particles, CunninghamFactorMatchesTheTextbookFormula) {
  // C_c = 1 + Kn (1.257 + 0.4 e^(−1.1/Kn)), Kn = 2λ/d, λ = 0.066 µm: 1.166 and 2.889.
  EXPECT_NEAR(cunningham_factor(1e-6, 0.066e-6), 1.166, 0.005 * 1.166);
  EXPECT_NEAR(cunningham_factor(0.1e-6, 0.066e-6), 2.889, 0.005 * 2.889);
}

TEST(Particles, ReleasedAtRestInUniformFlowFollowsTheStokesRelaxation) {
  const testing::UniformFlow flow(Vec3(1.0, 0.0, 0.0));
  const ParticleKind kind{10e-6, 1000.0};
  TraceOptions o;
  o.drag = DragLaw::stokes;
  const double tau = relaxation_time(kind, o.air);
  o.max_time = 5.0 * tau;
  o.path_spacing = 0.0;
  const ParticleResult r = track(flow, {Vec3::Zero(), Vec3::Zero(), 0}, kind, o, {}, true);
  ASSERT_EQ(r.fate, Fate::max_time);
  EXPECT_NEAR(r.time, 5.0 * tau, 1e-12 * tau);
  const double expected = 1.0 - std::exp(-5.0);
  EXPECT_NEAR(r.end_velocity[0], expected, 1e-6 * expected);
  EXPECT_NEAR(r.end_velocity.tail<2>().norm(), 0.0, 1e-12);
  // Every recorded point on the way, and the distance U(t − τ(1 − e^(−t/τ))).
  for (const PathPoint& p : r.path) {
    const double u = 1.0 - std::exp(-p.time / tau);
    EXPECT_NEAR(p.speed, u, 1e-6 * std::max(u, 1e-3)) << "t/τ " << p.time / tau;
  }
  const double x = 5.0 * tau - tau * expected;
  EXPECT_NEAR(r.end[0], x, 1e-6 * x);
  std::printf("[ info ] tau %.4e s, %ld steps\n", tau, r.steps);
}

TEST(Particles, SettleAtTheTerminalSpeedInStillAir) {
  const testing::UniformFlow still(Vec3::Zero());
  const ParticleKind kind{10e-6, 1000.0};
  TraceOptions o;
  o.gravity = Vec3(0.0, 0.0, -9.81);
  const double tau = relaxation_time(kind, o.air);
  o.max_time = 30.0 * tau;
  const double terminal = settling_speed(kind, o.air, 9.81);
  EXPECT_NEAR(terminal, 3.06e-3, 0.01 * 3.06e-3);  // VERIFICATION.md §6
  o.drag = DragLaw::stokes;
  const ParticleResult stokes = track(still, {Vec3::Zero(), Vec3::Zero(), 0}, kind, o, {}, false);
  EXPECT_NEAR(-stokes.end_velocity[2], terminal, 1e-3 * terminal);
  EXPECT_NEAR(stokes.end_velocity.head<2>().norm(), 0.0, 1e-15);
  // With Schiller–Naumann the drag balances gravity at f(Re_p) v = τ g (1 − ρ/ρ_p).
  o.drag = DragLaw::schiller_naumann;
  const ParticleResult sn = track(still, {Vec3::Zero(), Vec3::Zero(), 0}, kind, o, {}, false);
  const double v = -sn.end_velocity[2];
  const double re = o.air.density * v * kind.diameter / o.air.viscosity;
  EXPECT_LT(v, terminal);
  EXPECT_NEAR(drag_factor(DragLaw::schiller_naumann, re) * v, terminal, 1e-6 * terminal);
}

// The centrifugal drift that deposits particles in a bend: in air turning at Ω, a particle
// with Stokes drag obeys τ z'' + z' = iΩ z (z = x + iy), so z = A e^(s₁t) + B e^(s₂t) with
// τ s² + s − iΩ = 0; released with the air's velocity it spirals out at Re s₁ ≈ τΩ². Three
// turns at Ωτ = 0.05 (the radius grows by e^(3·2π·0.05) ≈ 2.5) with the default step control
// and a cell of a tenth of the start radius.
TEST(Particles, InertialParticleSpiralsOutOfSolidBodyRotationAsTheClosedForm) {
  const double r0 = 0.01, omega = 100.0;
  const testing::SolidBodyRotation flow(omega, 0.1 * r0);
  TraceOptions o;
  o.drag = DragLaw::stokes;
  o.path_spacing = 0.0;
  const double d = 10e-6, tau = 0.05 / omega;
  const ParticleKind kind{
      d, 18.0 * o.air.viscosity * tau / (d * d * cunningham_factor(d, o.air.mean_free_path))};
  ASSERT_NEAR(relaxation_time(kind, o.air), tau, 1e-12 * tau);
  o.max_time = 3.0 * 2.0 * M_PI / omega;
  const Vec3 x0(r0, 0.0, 0.0);
  const ParticleResult r = track(flow, {x0, std::nullopt, 0}, kind, o, {}, false);
  ASSERT_EQ(r.fate, Fate::max_time);
  using C = std::complex<double>;
  const C root = std::sqrt(C(1.0, 4.0 * omega * tau));
  const C s1 = (-1.0 + root) / (2.0 * tau), s2 = (-1.0 - root) / (2.0 * tau);
  const C z0(r0, 0.0), v0 = C(0.0, omega) * z0;
  const C a = (v0 - s2 * z0) / (s1 - s2), b = z0 - a;
  const C z = a * std::exp(s1 * r.time) + b * std::exp(s2 * r.time);
  EXPECT_GT(std::abs(z), 2.0 * r0);  // the drift is what is tested
  // The radius to 1e-4; the angle, an error accumulated over three turns, to 1e-3 rad.
  EXPECT_NEAR(r.end.head<2>().norm(), std::abs(z), 1e-4 * std::abs(z));
  EXPECT_NEAR(std::remainder(std::atan2(r.end[1], r.end[0]) - std::arg(z), 2.0 * M_PI), 0.0, 1e-3);
  EXPECT_NEAR(r.end[2], 0.0, 1e-15);
  std::printf("[ info ] r/r0 %.6f (closed form %.6f), %ld steps\n", r.end.head<2>().norm() / r0,
              std::abs(z) / r0, r.steps);
}

TEST(Particles, TracersInPoiseuilleFlowKeepTheirRadiusAndTakeTheAnalyticTime) {
  const double radius = 1e-3, length = 20.0 * radius, mean = 0.5;
  const testing::PoiseuillePipe pipe(radius, length, mean);
  TraceOptions o;
  o.path_spacing = 0.0;
  for (double r0 : {0.0, 0.3, 0.6, 0.8, 0.95}) {
    const Vec3 x0(r0 * radius * std::cos(0.7), r0 * radius * std::sin(0.7), 0.0);
    const ParticleResult r = track(pipe, {x0, std::nullopt, 0}, {}, o, {}, true);
    ASSERT_EQ(r.fate, Fate::outlet) << "r0 " << r0;
    double drift = 0.0;
    for (const PathPoint& p : r.path)
      drift = std::max(drift, std::abs(p.x.head<2>().norm() - r0 * radius));
    const double expected = length / (2.0 * mean * (1.0 - r0 * r0));
    EXPECT_LT(drift, 1e-3 * radius) << "r0 " << r0;
    EXPECT_NEAR(r.time, expected, 1e-3 * expected) << "r0 " << r0;
    EXPECT_NEAR(r.length, length, 1e-9 * length);
  }
}

TEST(Particles, PlaneCrossingsAreInterpolatedOnTheStep) {
  const double radius = 1e-3, length = 20.0 * radius, mean = 0.5;
  const testing::PoiseuillePipe pipe(radius, length, mean);
  const std::vector<Plane> planes{{Vec3(0, 0, 0.25 * length), Vec3::UnitZ()},
                                  {Vec3(0, 0, 0.5 * length), Vec3::UnitZ()}};
  const ParticleResult r =
      track(pipe, {Vec3(0.5 * radius, 0.0, 0.0), std::nullopt, 0}, {}, {}, planes, false);
  ASSERT_EQ(r.crossings.size(), 2u);
  const double speed = 2.0 * mean * 0.75;
  for (const Crossing& c : r.crossings) {
    const double z = planes[static_cast<std::size_t>(c.plane)].point[2];
    EXPECT_NEAR(c.x[2], z, 1e-12);
    EXPECT_NEAR(c.time, z / speed, 1e-6 * z / speed);
  }
}

TEST(Particles, InertialParticleSettlingInAPipeDepositsOnTheWall) {
  const double radius = 1e-3;
  const testing::PoiseuillePipe pipe(radius, 1.0, 0.01);
  TraceOptions o;
  o.gravity = Vec3(0.0, -9.81, 0.0);
  const ParticleKind kind{20e-6, 1000.0};
  const ParticleResult r = track(pipe, {Vec3(0.0, 0.0, 0.0), std::nullopt, 0}, kind, o, {}, false);
  ASSERT_EQ(r.fate, Fate::wall);
  EXPECT_EQ(pipe.patch_names()[static_cast<std::size_t>(r.patch)], "wall");
  // The centre stops d/2 from the wall; the contact point is on it.
  EXPECT_NEAR(r.end.head<2>().norm(), radius - 0.5 * kind.diameter, 1e-12);
  EXPECT_NEAR(r.contact.head<2>().norm(), radius, 1e-12);
  EXPECT_LT(r.contact[1], 0.0);
}

}  // namespace
}  // namespace naris::particles
