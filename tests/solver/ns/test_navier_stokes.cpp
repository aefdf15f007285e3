// The stabilized equal-order Navier–Stokes discretization against exact solutions
// (VERIFICATION.md §2): the Couette patch test at round-off on tet-only, hex-only and MVE
// hybrid meshes, and the steady Ethier–Steinman (Beltrami) flow converging at the expected
// orders at ν = 1 and ν = 0.01.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <random>

#include "solver/continuation/arclength.h"
#include "solver/fem/quadrature.h"
#include "solver/fem/reference_element.h"
#include "solver/nonlinear/bordered_step.h"
#include "solver/nonlinear/forcing_term.h"
#include "solver/nonlinear/navier_stokes_solver.h"
#include "solver/nonlinear/preconditioner_reuse.h"
#include "solver/ns/oseen_element.h"
#include "solver/parallel/petsc.h"
#include "tests/solver/manufactured.h"
#include "tests/solver/meshes.h"
#include "tests/solver/residual_history.h"

namespace naris::ns {
namespace {

using continuation::aim_along_secant;
using continuation::arclength_predictor;
using nonlinear::ArclengthConstraint;
using nonlinear::forcing_term;
using nonlinear::LinearProblem;
using nonlinear::NonlinearOptions;
using nonlinear::NonlinearReport;
using nonlinear::PreconditionerReuse;
using nonlinear::solve_navier_stokes;
using nonlinear::velocity_inner_product;

using testing::beltrami;
using testing::beltrami_pressure;
using testing::Errors;
using testing::Exact;
using testing::exact_on_boundary;
using testing::ExactScalar;
using testing::l2_errors;
constexpr double kD = testing::kBeltramiD;

class PetscEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { session_ = std::make_unique<petsc::Session>(); }
  void TearDown() override { session_.reset(); }

 private:
  std::unique_ptr<petsc::Session> session_;
};
[[maybe_unused]] const auto* const kPetsc =
    ::testing::AddGlobalTestEnvironment(new PetscEnvironment);

// Inside a ball of radius 0.9 (its surface cuts the grid anywhere: hexes, pyramids, tets).
double ball(const Eigen::Vector3d& x) {
  return 0.9 - (x - Eigen::Vector3d(0.013, -0.021, 0.017)).norm();
}

TEST(NavierStokes, CouettePatchTestIsExactOnEveryCellType) {
  const double gamma = 1.7;
  const Exact u = [&](const Eigen::Vector3d& x) { return Eigen::Vector3d(gamma * x[1], 0, 0); };
  const ExactScalar p = [](const Eigen::Vector3d&) { return 0.25; };
  const std::pair<const char*, HybridMesh> meshes[] = {
      {"hex", testing::box_hex(4)},
      {"tet", testing::box_tet(4)},
      {"mve ball", testing::mve_mesh(ball, -1.0, 1.0, 0.25)}};
  for (const auto& [name, mesh] : meshes) {
    if (std::string(name) == "mve ball") {
      EXPECT_GT(mesh.pyramids.size(), 0u);
      EXPECT_GT(mesh.hexes.size(), 0u);
      EXPECT_GT(mesh.tets.size(), 0u);
    }
    for (const double nu : {1.0, 0.01}) {
      // A direct solve, so that round-off is the only error left.
      PetscOptionsSetValue(nullptr, "-patch_ksp_type", "preonly");
      PetscOptionsSetValue(nullptr, "-patch_pc_type", "lu");
      NonlinearOptions options;
      options.options_prefix = "patch_";
      NonlinearReport report;
      const FlowField f = solve_navier_stokes(
          mesh, ns::FlowProblem{1.0 / nu, {}, exact_on_boundary(mesh, u, p)}, options, &report);
      double eu = 0, ep = 0;
      for (std::size_t n = 0; n < mesh.nodes.size(); ++n) {
        eu = std::max(eu, (f.velocity[n] - u(mesh.nodes[n])).norm());
        ep = std::max(ep, std::abs(f.pressure[n] - 0.25));
      }
      std::printf("[ info ] Couette on %s, nu %g: max error u %.2e, p %.2e, %d Picard steps\n",
                  name, nu, eu, ep, report.iterations);
      EXPECT_LT(eu, 1e-11) << name << " nu " << nu;
      EXPECT_LT(ep, 1e-10) << name << " nu " << nu;
      EXPECT_TRUE(report.converged);
    }
  }
}

struct Rates {
  std::vector<double> h, eu, ep;
};

Rates ethier_steinman(const std::string& kind, const std::vector<int>& sizes, double nu) {
  Rates r;
  const BodyForce force = [nu](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return nu * kD * kD * beltrami(x);
  };
  for (int n : sizes) {
    const HybridMesh mesh = testing::convergence_mesh(kind, n);
    NonlinearOptions options;
    options.tolerance = 1e-9;
    NonlinearReport report;
    const FlowField f = solve_navier_stokes(
        mesh,
        ns::FlowProblem{1.0 / nu, force, exact_on_boundary(mesh, beltrami, beltrami_pressure)},
        options, &report);
    EXPECT_TRUE(report.converged) << kind << " n " << n;
    const Errors e = l2_errors(mesh, f, beltrami, beltrami_pressure);
    r.h.push_back(2.0 / n);
    r.eu.push_back(e.velocity);
    r.ep.push_back(e.pressure);
    std::printf(
        "[ info ] Ethier-Steinman %s nu %g h %.4f: %zu cells, %d Picard steps, L2 u %.3e, p %.3e",
        kind.c_str(), nu, 2.0 / n, mesh.cell_count(), report.iterations, e.velocity, e.pressure);
    if (r.h.size() > 1) {
      const std::size_t k = r.h.size() - 1;
      const double s = std::log(r.h[k - 1] / r.h[k]);
      std::printf("  rates u %.2f, p %.2f", std::log(r.eu[k - 1] / r.eu[k]) / s,
                  std::log(r.ep[k - 1] / r.ep[k]) / s);
    }
    std::printf("\n");
  }
  return r;
}

// Over the last two refinements: velocity ≈ h², pressure at least h (VERIFICATION.md §2).
void expect_orders(const Rates& r, const std::string& what) {
  const std::size_t k = r.h.size() - 1;
  const double s = std::log(r.h[k - 1] / r.h[k]);
  EXPECT_GT(std::log(r.eu[k - 1] / r.eu[k]) / s, 1.8) << what;
  EXPECT_GT(std::log(r.ep[k - 1] / r.ep[k]) / s, 1.0) << what;
}

TEST(NavierStokes, EthierSteinmanConvergesAtSecondOrderInVelocity) {
  for (const double nu : {1.0, 0.01})
    for (const char* kind : {"hex", "tet", "mve-box", "mve-ball"})
      expect_orders(ethier_steinman(kind, {4, 8, 16}, nu),
                    std::string(kind) + " nu " + std::to_string(nu));
}

// Picard alone, Newton, Newton under pseudo-transient continuation, FiDAP's segregated scheme
// and GMRES preconditioned by its sweep take different paths to the same discrete solution:
// the pseudo-time term, the line search and the segregated sweep change the matrix and the
// steps, never the residual being driven to zero.
// The steady Ethier–Steinman flow at ν = 0.01 on the MVE ball at n = 8: mesh, force and the
// exact velocity on the boundary.
struct BeltramiBall {
  double nu = 0.01;
  BodyForce force = [nu = nu](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return nu * kD * kD * beltrami(x);
  };
  HybridMesh mesh = testing::convergence_mesh("mve-ball", 8);
  DirichletConditions bc = exact_on_boundary(mesh, beltrami, beltrami_pressure);
};

TEST(NavierStokes, PicardNewtonPseudoTimeAndSegregatedReachTheSameSolution) {
  const BeltramiBall problem;
  const auto& [nu, force, mesh, bc] = problem;
  NonlinearOptions picard, newton, pseudo, segregated, preconditioned;
  for (NonlinearOptions* o : {&picard, &newton, &pseudo, &segregated, &preconditioned}) {
    o->tolerance = 1e-10;
    o->max_iterations = 400;
  }
  picard.newton = false;
  pseudo.pseudo_cfl = 1.0;
  segregated.scheme = NonlinearOptions::Scheme::segregated;
  preconditioned.scheme = NonlinearOptions::Scheme::segregated_krylov;
  std::vector<FlowField> fields;
  std::vector<int> steps;
  for (const NonlinearOptions* o : {&picard, &newton, &pseudo, &segregated, &preconditioned}) {
    NonlinearReport report;
    fields.push_back(solve_navier_stokes(mesh, ns::FlowProblem{1.0 / nu, force, bc}, *o, &report));
    EXPECT_TRUE(report.converged);
    steps.push_back(report.iterations);
  }
  std::printf(
      "[ info ] nonlinear steps: Picard %d, Newton %d, Newton with pseudo-time %d, segregated "
      "%d, segregated-preconditioned Newton %d\n",
      steps[0], steps[1], steps[2], steps[3], steps[4]);
  double scale = 0.0;
  for (const auto& v : fields[1].velocity) scale = std::max(scale, v.norm());
  for (const std::size_t k : {std::size_t{0}, std::size_t{2}, std::size_t{3}, std::size_t{4}}) {
    double du = 0.0;
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
      du = std::max(du, (fields[k].velocity[n] - fields[1].velocity[n]).norm());
    EXPECT_LT(du, 1e-6 * scale) << "run " << k;
  }
  // Newton converges in fewer steps than Picard's linear rate allows.
  EXPECT_LT(steps[1], steps[0]);
}

// Newton's method with every linear solve exact to 1e-12 converges quadratically only if its
// matrix is the residual's whole derivative — including that of the reconstructed viscous
// term, which reaches two cells out (reconstruction_derivative.h). With that term lagged the
// ratio of successive residuals stalls near a constant; here each ratio must fall below a
// tenth of the one before once the iteration is close (Beltrami flow in the MVE ball, ν = 0.01,
// a Picard start).
TEST(NavierStokes, NewtonConvergesQuadraticallyWithTheWholeDerivative) {
  const BeltramiBall problem;
  NonlinearOptions o;
  o.tolerance = 1e-13;
  o.linear_tolerance = o.loosest_linear_tolerance = 1e-12;
  o.max_iterations = 30;
  NonlinearReport report;
  solve_navier_stokes(problem.mesh, ns::FlowProblem{1.0 / problem.nu, problem.force, problem.bc}, o,
                      &report);
  const auto& h = report.residuals;
  for (std::size_t k = 0; k < h.size(); ++k) std::printf("[ info ] residual %zu: %.3e\n", k, h[k]);
  EXPECT_TRUE(testing::ends_quadratically(h));
}

// naris's own work shows in PETSc's profile (-log_view) beside PETSc's events: every
// assembly, and the whole derivative's, once per Newton step that uses it.
TEST(NavierStokes, AssemblyIsAnEventOfPetscsProfile) {
  petsc::check(PetscLogDefaultBegin(), "PetscLogDefaultBegin");
  const auto count = [](const char* name) {
    PetscLogEvent event = -1;
    petsc::check(PetscLogEventGetId(name, &event), "PetscLogEventGetId");
    if (event < 0) return 0;
    PetscEventPerfInfo info{};
    petsc::check(PetscLogEventGetPerfInfo(0, event, &info), "PetscLogEventGetPerfInfo");
    return info.count;
  };
  const int assemblies = count("NSAssembly"), derivatives = count("NSWholeDerivative");
  const BeltramiBall problem;
  NonlinearOptions o;
  o.tolerance = 1e-10;
  o.max_iterations = 30;
  NonlinearReport report;
  solve_navier_stokes(problem.mesh, ns::FlowProblem{1.0 / problem.nu, problem.force, problem.bc}, o,
                      &report);
  ASSERT_TRUE(report.converged);
  // One assembly per nonlinear step and the Stokes start; the residual that ends the
  // iteration is an assembly too. Newton follows the Picard steps with the whole derivative.
  EXPECT_EQ(count("NSAssembly") - assemblies, report.iterations + 2);
  EXPECT_EQ(count("NSWholeDerivative") - derivatives, report.iterations - o.picard_steps);
}

// A pseudo-arclength step lands on the branch of steady solutions: from the solutions at Re 80
// and 90 (Beltrami data, the body force held fixed, so R(u, Re) is one smooth family) along
// their secant by its own length, forwards and backwards, it finds a point that satisfies the
// arclength constraint and is the solution that continuation in Re finds at the Re it reports.
TEST(NavierStokes, ArclengthStepFindsTheSolutionAtTheReItReports) {
  const BeltramiBall problem;
  const auto& [nu, force, mesh, bc] = problem;
  const parallel::NodeNumbering whole = parallel::whole_numbering(mesh.nodes.size());
  NonlinearOptions o;
  o.tolerance = 1e-11;
  o.linear_tolerance = o.loosest_linear_tolerance = 1e-10;
  const FlowField u80 = solve_navier_stokes(mesh, whole, ns::FlowProblem{80, force, bc}, o);
  const FlowField u90 =
      solve_navier_stokes(mesh, whole, ns::FlowProblem{90, force, bc}, o, nullptr, &u80);
  for (const bool forwards : {true, false}) {
    const FlowField& from = forwards ? u80 : u90;
    const FlowField& to = forwards ? u90 : u80;
    const double re_from = forwards ? 80 : 90, re_to = forwards ? 90 : 80;
    ArclengthConstraint c;
    c.origin = to;
    c.origin_reynolds = re_to;
    c.step =
        aim_along_secant(c, from, re_from, to, re_to, [&](const FlowField& a, const FlowField& b) {
          return velocity_inner_product(a, b, whole, PETSC_COMM_WORLD);
        });
    const FlowField guess = arclength_predictor(c);
    // The predictor's Re, 3 too far: the corrector has to bring Re back to the hyperplane.
    const double re_guess = re_to + c.step * c.tangent_reynolds;
    const double re_start = re_guess + (forwards ? 3.0 : -3.0);
    NonlinearReport report;
    const FlowField found = solve_navier_stokes(mesh, whole, ns::FlowProblem{re_start, force, bc},
                                                o, &report, &guess, &c);
    ASSERT_TRUE(report.converged) << (forwards ? "forwards" : "backwards");
    std::printf(
        "[ info ] arclength %s: predicted Re %.4f, started at %.4f, found Re %.4f in %d Newton "
        "steps\n",
        forwards ? "forwards" : "backwards", re_guess, re_start, report.reynolds,
        report.iterations);
    EXPECT_LT(std::abs(report.reynolds - re_guess), 1.0);
    // It moved along the branch by about the secant's length, in the tangent's direction.
    EXPECT_GT((report.reynolds - re_to) * c.tangent_reynolds, 0.0);
    EXPECT_NEAR(std::abs(report.reynolds - re_to), 10.0, 2.0);
    // On the hyperplane of the constraint …
    FlowField moved = found;
    for (std::size_t k = 0; k < moved.pressure.size(); ++k) moved.velocity[k] -= to.velocity[k];
    const double constraint = velocity_inner_product(c.tangent, moved, whole, PETSC_COMM_WORLD) +
                              c.tangent_reynolds * (report.reynolds - re_to) / (re_to * re_to) -
                              c.step;
    EXPECT_LT(std::abs(constraint), 1e-6 * c.step);
    // … and the solution at that Re.
    const FlowField direct = solve_navier_stokes(
        mesh, whole, ns::FlowProblem{report.reynolds, force, bc}, o, nullptr, &to);
    double du = 0.0, scale = 0.0;
    for (std::size_t k = 0; k < mesh.nodes.size(); ++k) {
      du = std::max(du, (found.velocity[k] - direct.velocity[k]).norm());
      scale = std::max(scale, direct.velocity[k].norm());
    }
    EXPECT_LT(du, 1e-7 * scale) << (forwards ? "forwards" : "backwards");
    // The branch's tangent there, against a central difference of solutions at Re ± 0.5: unit
    // in the constraint's metric, pointing on along the step.
    ASSERT_EQ(report.tangent.velocity.size(), mesh.nodes.size());
    const double re = report.reynolds;
    const FlowField above = solve_navier_stokes(mesh, whole, ns::FlowProblem{re + 0.5, force, bc},
                                                o, nullptr, &direct),
                    below = solve_navier_stokes(mesh, whole, ns::FlowProblem{re - 0.5, force, bc},
                                                o, nullptr, &direct);
    FlowField slope = above;  // du/dRe
    for (std::size_t k = 0; k < slope.pressure.size(); ++k) slope.velocity[k] -= below.velocity[k];
    const auto metric = [&](const FlowField& a, double a_re, const FlowField& b, double b_re) {
      return velocity_inner_product(a, b, whole, PETSC_COMM_WORLD) + a_re * b_re / (re * re);
    };
    const double t_re = report.tangent_reynolds;
    EXPECT_NEAR(metric(report.tangent, t_re, report.tangent, t_re), 1.0, 1e-12);
    EXPECT_GT(t_re * c.tangent_reynolds, 0.0);
    const double cosine =
        metric(report.tangent, t_re, slope, 1.0) / std::sqrt(metric(slope, 1.0, slope, 1.0));
    EXPECT_GT(std::abs(cosine), 1.0 - 1e-6) << (forwards ? "forwards" : "backwards");
    std::printf("[ info ] tangent against the central difference: 1 - cos = %.2e\n",
                1.0 - std::abs(cosine));
  }
}

// An iteration that crawls — here Picard held to 5 % steps, so the residual falls a few
// percent a step — is given up once it has not halved over `stall_steps` steps, long before
// max_iterations; left alone it would go on.
TEST(NavierStokes, StalledIterationGivesUpEarly) {
  const BeltramiBall problem;
  NonlinearOptions crawl;
  crawl.newton = false;
  crawl.relaxation = 0.05;
  crawl.max_iterations = 60;
  crawl.stall_steps = 4;
  NonlinearReport report;
  solve_navier_stokes(problem.mesh, ns::FlowProblem{1.0 / problem.nu, problem.force, problem.bc},
                      crawl, &report);
  EXPECT_FALSE(report.converged);
  ASSERT_GE(report.residuals.size(), 5u);
  EXPECT_LE(report.iterations, 8);
  const auto& h = report.residuals;
  EXPECT_GT(h.back(), 0.5 * h[h.size() - 5]);  // the reason it stopped
  EXPECT_LT(h.back(), h.front());              // still falling: only slowly
}

// Keeping the preconditioner changes the linear iterations, not the answer: Newton on the
// Beltrami ball to 1e-10 with and without it. Without, every linear solve (the Stokes one and
// one per nonlinear step) builds its own.
TEST(NavierStokes, KeptPreconditionerReachesTheSameSolution) {
  const BeltramiBall problem;
  NonlinearOptions fresh, kept;
  for (NonlinearOptions* o : {&fresh, &kept}) o->tolerance = 1e-10;
  fresh.reuse_preconditioner = false;
  NonlinearReport fresh_report, kept_report;
  const FlowField a = solve_navier_stokes(
      problem.mesh, ns::FlowProblem{1.0 / problem.nu, problem.force, problem.bc}, fresh,
      &fresh_report);
  const FlowField b = solve_navier_stokes(
      problem.mesh, ns::FlowProblem{1.0 / problem.nu, problem.force, problem.bc}, kept,
      &kept_report);
  ASSERT_TRUE(fresh_report.converged);
  ASSERT_TRUE(kept_report.converged);
  EXPECT_EQ(fresh_report.preconditioner_builds, fresh_report.iterations + 1);
  EXPECT_LE(kept_report.preconditioner_builds, kept_report.iterations + 1);
  EXPECT_GT(kept_report.linear_iterations, 0);
  std::printf("[ info ] preconditioner builds: %d of %d solves fresh, %d of %d kept\n",
              fresh_report.preconditioner_builds, fresh_report.iterations + 1,
              kept_report.preconditioner_builds, kept_report.iterations + 1);
  double scale = 0.0, du = 0.0, dp = 0.0, pscale = 0.0;
  for (std::size_t k = 0; k < a.velocity.size(); ++k) {
    scale = std::max(scale, a.velocity[k].norm());
    pscale = std::max(pscale, std::abs(a.pressure[k]));
    du = std::max(du, (a.velocity[k] - b.velocity[k]).norm());
    dp = std::max(dp, std::abs(a.pressure[k] - b.pressure[k]));
  }
  EXPECT_LT(du, 1e-7 * scale);
  EXPECT_LT(dp, 1e-7 * pscale);
}

// The rule itself, on made-up costs (seconds here; the solver counts operations): a build
// costs 2 s, a fresh solve 100 iterations of 10 ms for 3 decades (a tolerance of 1e-3). A kept
// preconditioner stays while the iterations it adds cost less than a build.
TEST(PreconditionerReuse, KeepsWhileTheAddedIterationsCostLessThanABuild) {
  PreconditionerReuse reuse(true);
  EXPECT_FALSE(reuse.keeps(LinearProblem::stokes));  // nothing built yet
  reuse.built(LinearProblem::newton, 2.0, 1.0, 100, 3.0);
  EXPECT_TRUE(reuse.keeps(LinearProblem::newton));
  EXPECT_FALSE(reuse.keeps(LinearProblem::picard));  // another kind of matrix
  EXPECT_EQ(reuse.iteration_budget(3.0), 100 + 200 + 1);
  reuse.kept(1.5, 150, 3.0);  // 50 more, 0.5 s < 2 s
  EXPECT_TRUE(reuse.keeps(LinearProblem::newton));
  reuse.kept(3.0, 300, 3.0);  // 200 more, exactly a build: still kept
  EXPECT_TRUE(reuse.keeps(LinearProblem::newton));
  reuse.kept(3.1, 310, 3.0);  // 210 more, 2.1 s > 2 s
  EXPECT_FALSE(reuse.keeps(LinearProblem::newton));
  reuse.built(LinearProblem::newton, 2.0, 1.0, 100, 3.0);
  EXPECT_TRUE(reuse.keeps(LinearProblem::newton));
  reuse.abandoned();  // a kept solve ran out of its budget: no more keeping
  reuse.built(LinearProblem::newton, 2.0, 1.0, 100, 3.0);
  EXPECT_FALSE(reuse.keeps(LinearProblem::newton));

  PreconditionerReuse off(false);
  off.built(LinearProblem::newton, 2.0, 1.0, 100, 3.0);
  EXPECT_FALSE(off.keeps(LinearProblem::newton));
}

// Solves to other tolerances are judged by iterations per decade: a fresh build that took 20
// iterations for one decade (a tolerance of 0.1) makes 60 the fresh count for three.
TEST(PreconditionerReuse, ComparesSolvesToOtherTolerancesPerDecade) {
  PreconditionerReuse reuse(true);
  reuse.built(LinearProblem::newton, 2.0, 0.2, 20, 1.0);
  EXPECT_EQ(reuse.iteration_budget(3.0), 60 + 200 + 1);
  reuse.kept(2.5, 250, 3.0);  // 190 more than 60: 1.9 s < 2 s
  EXPECT_TRUE(reuse.keeps(LinearProblem::newton));
  reuse.kept(0.8, 80, 0.5);  // 70 more than 10: 0.7 s < 2 s
  EXPECT_TRUE(reuse.keeps(LinearProblem::newton));
  reuse.kept(2.3, 230, 1.0);  // 210 more than 20: 2.1 s > 2 s
  EXPECT_FALSE(reuse.keeps(LinearProblem::newton));
}

// Eisenstat–Walker's choice 2: γ·ratio², the safeguard after a loose step, the bounds.
TEST(ForcingTerm, FollowsTheSquareOfTheResidualRatioWithinItsBounds) {
  EXPECT_DOUBLE_EQ(forcing_term(1.0, INFINITY, 0.0, 1e-3, 0.1), 0.1);  // no ratio yet
  EXPECT_DOUBLE_EQ(forcing_term(0.2, 1.0, 1e-3, 1e-3, 0.1), 0.9 * 0.04);
  EXPECT_DOUBLE_EQ(forcing_term(0.9, 1.0, 1e-3, 1e-3, 0.1), 0.1);    // slow fall: loosest
  EXPECT_DOUBLE_EQ(forcing_term(1e-3, 1.0, 1e-3, 1e-3, 0.1), 1e-3);  // fast fall: tightest
  // After η = 0.5 a sudden drop keeps γ η² = 0.225 (then bounded to 0.3).
  EXPECT_DOUBLE_EQ(forcing_term(1e-3, 1.0, 0.5, 1e-3, 0.3), 0.9 * 0.25);
  // No safeguard below γ η² = 0.1.
  EXPECT_DOUBLE_EQ(forcing_term(1e-2, 1.0, 0.3, 1e-5, 0.3), 0.9 * 1e-4);
  // Bounds equal: a fixed tolerance.
  EXPECT_DOUBLE_EQ(forcing_term(0.5, 1.0, 1e-3, 1e-3, 1e-3), 1e-3);
}

// The Newton matrix is the derivative of the element residual: against central differences of
// R(u, p) on distorted cells of every type, at a cell Reynolds number where τ depends on u
// (h = 0.05, ν = 0.01, |u| ≤ 1), without the lagged viscous reconstruction: exact to the
// differencing error, while Picard's K(u) leaves out a large part.
template <class E>
void check_newton_derivative() {
  constexpr int N = E::nodes;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(-0.1, 0.1), value(-1.0, 1.0);
  Eigen::Matrix<double, N, 3> X, a, da;
  Eigen::Matrix<double, N, 1> p, dp;
  for (int i = 0; i < N; ++i) {
    for (int c = 0; c < 3; ++c) {
      X(i, c) = 0.05 * (E::node(i)[c] + jitter(rng));
      a(i, c) = value(rng);
      da(i, c) = value(rng);
    }
    p[i] = value(rng);
    dp[i] = value(rng);
  }
  const double nu = 0.01;
  const auto force = [](const Eigen::Vector3d& x) { return Eigen::Vector3d(x[1], -x[0], 1.0); };
  ElementSystem<N> at, plus, minus;
  oseen_element<E>(X, a, nullptr, nu, force, at, p, Linearization::newton);
  const double eps = 1e-6;
  oseen_element<E>(X, a + eps * da, nullptr, nu, force, plus, p + eps * dp,
                   Linearization::picard_residual);
  oseen_element<E>(X, a - eps * da, nullptr, nu, force, minus, p - eps * dp,
                   Linearization::picard_residual);
  Eigen::Matrix<double, 4 * N, 1> step;
  for (int i = 0; i < N; ++i) {
    step.template segment<3>(4 * i) = da.row(i).transpose();
    step[4 * i + 3] = dp[i];
  }
  const Eigen::Matrix<double, 4 * N, 1> derivative = (plus.R - minus.R) / (2 * eps);
  const double newton_error = (derivative - at.K * step).norm();
  const double picard_error = (derivative - (at.K - at.newton) * step).norm();
  EXPECT_GT(picard_error, 1e-2 * derivative.norm());
  EXPECT_LT(newton_error, 1e-7 * derivative.norm()) << "Picard misses " << picard_error;
}

TEST(OseenElement, NewtonMatrixIsTheResidualsDerivative) {
  check_newton_derivative<fem::Tet4>();
  check_newton_derivative<fem::Pyr5>();
  check_newton_derivative<fem::Hex8>();
}

}  // namespace
}  // namespace naris::ns
