#pragma once
// Steady incompressible Navier–Stokes on a hybrid mesh: Picard steps on the stabilized Oseen
// problem, then Newton's method (oseen_element.h), each a damped step with backtracking,
// assembled into one PETSc matrix with 4×4 blocks per node pair (preallocated from the node
// graph) and solved inexactly with a PETSc KSP (options prefix "ns_"; GMRES on ILU(1) by
// default). Convergence is judged on the full nonlinear residual.
#include <petscsys.h>  // MPI_Comm, without the MPI C++ bindings

#include <Eigen/Dense>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "hybrid_mesh.h"
#include "parallel/partition.h"

namespace naris::ns {

using BodyForce = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

struct FlowField {
  std::vector<Eigen::Vector3d> velocity;  // per node
  std::vector<double> pressure;           // per node
};

// Velocity fixed at some nodes (no-slip walls, inlets, exact data in tests) and optionally the
// pressure at one node (when no boundary sets its level).
struct DirichletConditions {
  std::vector<NodeId> nodes;
  std::vector<Eigen::Vector3d> values;
  std::optional<std::pair<NodeId, double>> pressure_pin;
};

struct PicardOptions {
  int max_iterations = 50;
  double tolerance = 1e-8;  // on the residual 2-norm relative to that of the load (F with data)
  double absolute_tolerance = 1e-13;
  double relaxation = 1.0;  // U ← U + ω (U* − U)
  // Newton's method (oseen_element.h: only the reconstructed viscous term stays lagged) after
  // this many Picard steps.
  bool newton = true;
  int picard_steps = 2;
  // Each linear solve (for the correction, from a zero guess) stops when its residual has
  // fallen by this factor: the nonlinear residual times this is what the step leaves unsolved.
  double linear_tolerance = 1e-3;
  // … at the tightest: the tolerance of each step follows how fast the nonlinear residual falls
  // (forcing_term.h), between linear_tolerance and this (equal: a fixed tolerance).
  double loosest_linear_tolerance = 0.1;
  // Pseudo-transient continuation: the first step's Courant number (0: off), raised as the
  // residual falls (as (R_{k−1}/R_k)², at most 4× a step).
  double pseudo_cfl = 0.0;
  // Give up (not converged) when the residual has not halved over this many steps (0: never):
  // a stalled attempt is better retried another way than run to max_iterations.
  int stall_steps = 0;
  // coupled: each step solves the whole linearized system (GMRES on ILU); segregated: one
  // sweep of FiDAP's segregated scheme (segregated_step.h) per Picard step, relaxed by
  // α_u and α_p — Picard only; segregated_krylov: GMRES on the whole system preconditioned by
  // that sweep (one AMG V-cycle per field, no relaxation).
  enum class Scheme { coupled, segregated, segregated_krylov };
  Scheme scheme = Scheme::coupled;
  double velocity_relaxation = 0.7, pressure_relaxation = 0.3;
  std::string options_prefix = "ns_";
  // Keep the preconditioner (the ILU factors) from one nonlinear step to the next while that
  // pays: it is rebuilt when the linearization changes kind (Stokes, Picard, Newton), and when
  // the iterations it added over the first solve after the last rebuild cost more time than a
  // rebuild (both measured); once a solve with a kept one runs out of its iteration budget or
  // fails, every later solve of this call rebuilds. The converged answer is
  // the same either way; only the linear iterations differ.
  bool reuse_preconditioner = true;
  // The ranks that share the system (MPI_COMM_NULL: PETSC_COMM_WORLD).
  MPI_Comm communicator = MPI_COMM_NULL;
  bool log_iterations = false;  // a line per step (residual, relaxation, linear iterations)
  // Progress on long work: without log_iterations, a step's line once this many seconds have
  // passed since the solve began or since the last such line; and within a linear solve that
  // runs longer, a line this often (on the neonate subdivided to 4.2 M cells one took 10 min).
  // 0: none.
  double progress_seconds = 60.0;
  // Outflow stabilization on this patch (the outlet; −1: none) with coefficient β ∈ [0, 1].
  int backflow_patch = -1;
  double backflow_beta = 1.0;
};

// Pseudo-arclength continuation (Keller 1977): the Reynolds number joins the unknowns, and one
// equation more fixes how far along the branch's tangent (t_u, t_Re) the solution lies,
//   N(u, Re) = ⟨t_u, u − u₁⟩ + t_Re (Re − Re₁) / Re₁² − Δs = 0,
// with ⟨·,·⟩ the mean over the nodes of the velocities' dot product (pressure left out: it
// follows the velocity) and Re measured relative to Re₁. Where a branch of steady solutions
// turns back (a turning point, where the Jacobian is singular and no solution lies just beyond
// in Re) the iteration follows it around, which continuation in Re alone cannot. Newton's step
// on this bordered system by block elimination: J a = −R and J b = −∂R/∂Re (a difference
// quotient), then δRe from the constraint, which is linear, and δu = a + δRe b.
struct ArclengthConstraint {
  FlowField origin;   // u₁: the last point on the branch, on the piece (nondimensional)
  FlowField tangent;  // t_u on the piece (its pressure is not used)
  double origin_reynolds = 0.0;   // Re₁
  double tangent_reynolds = 0.0;  // t_Re
  double step = 0.0;              // Δs
};

struct PicardReport {
  std::vector<double> residuals;  // nonlinear residual 2-norm before each solve, and the last
  int iterations = 0;
  int preconditioner_builds = 0;  // linear solves that set the preconditioner up anew
  int linear_iterations = 0;
  bool converged = false;
  double reynolds = 0.0;  // with an arclength constraint: the Re of the answer (else 1/ν)
  // With an arclength constraint, when the last step was Newton's: the branch's unit tangent
  // at the answer, (du/dRe, 1) from that step's ∂R/∂Re solve, scaled to unit length in the
  // constraint's metric at the answer's Re and pointing the constraint's way (on the piece;
  // its pressure is dp/dRe alike). Empty otherwise.
  FlowField tangent;
  double tangent_reynolds = 0.0;
};

// Solves with viscosity ν (1/Re in nondimensional form) and body force f (may be empty).
// `initial` (optional) warm-starts; otherwise the first iterate is the Stokes solution.
// Each rank of the communicator passes its piece of the mesh (parallel::mesh_piece; the whole
// mesh with parallel::whole_numbering on one rank), the conditions and the initial field on
// that piece, and gets the field on it back.
// With `arclength` the Reynolds number is an unknown too (Newton steps only, no pseudo-time):
// ν = 1/Re of the predictor, `initial` the predicted field, and report->reynolds the Re found.
FlowField solve_navier_stokes(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                              double nu, const BodyForce& force,
                              const DirichletConditions& conditions, const PicardOptions& options,
                              PicardReport* report = nullptr, const FlowField* initial = nullptr,
                              const ArclengthConstraint* arclength = nullptr);

// ⟨a, b⟩ of the arclength constraint: the mean over the whole mesh's nodes of a_u·b_u, from
// each rank's owned nodes (the first `numbering.owned` of its piece). Collective.
double velocity_inner_product(const FlowField& a, const FlowField& b,
                              const parallel::NodeNumbering& numbering, MPI_Comm comm);

// Points the constraint's tangent along the secant from (from, Re₀) to (to, Re₁): (to − from,
// Re₁ − Re₀) divided by its length in the constraint's metric, √(⟨δu, δu⟩ + (δRe/Re₁)²), which
// it returns (the step that would reach `to` again from `from`). Collective.
double aim_along_secant(ArclengthConstraint& c, const FlowField& from, double re_from,
                        const FlowField& to, double re_to, const parallel::NodeNumbering& numbering,
                        MPI_Comm comm);

// The predictor of a step: origin + step · tangent (its Re: origin_reynolds + step · t_Re).
FlowField arclength_predictor(const ArclengthConstraint& c);

// The same from the whole mesh on every rank: the ranks cut it into pieces, solve, and each
// gets the whole field back. For tests and small problems.
FlowField solve_navier_stokes(const HybridMesh& mesh, double nu, const BodyForce& force,
                              const DirichletConditions& conditions, const PicardOptions& options,
                              PicardReport* report = nullptr, const FlowField* initial = nullptr);

// A whole field's values on a piece, and conditions on the whole mesh as the piece's.
FlowField local_field(const FlowField& whole, const parallel::NodeNumbering& numbering);
DirichletConditions local_conditions(const DirichletConditions& whole,
                                     const parallel::NodeNumbering& numbering);
// The whole field from the owned nodes of every rank's piece: on every rank (`root` < 0) or on
// rank `root` only (the others get an empty field). Collective over `comm`.
FlowField gather_field(const FlowField& local, const parallel::NodeNumbering& numbering,
                       MPI_Comm comm, int root = -1);

}  // namespace naris::ns
