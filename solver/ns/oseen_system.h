#pragma once
// The discrete steady Navier–Stokes problem on this rank's piece of the mesh: the stabilized
// Oseen (Picard) or Newton matrix with 4×4 blocks per node pair, its right-hand side and the
// nonlinear residual, assembled from the element kernels of oseen_element.h; plus the pieces
// the nonlinear solve adds (pseudo-time term, Newton's whole derivative as an operator).
#include <petscksp.h>

#include <Eigen/Dense>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_field.h"
#include "solver/ns/flow_problem.h"
#include "solver/ns/oseen_element.h"
#include "solver/ns/reconstruction_derivative.h"
#include "solver/parallel/block_assembly.h"
#include "solver/parallel/partition.h"
#include "solver/parallel/petsc.h"

namespace naris::ns {

// The system over the ranks of `comm`: each rank holds its piece of the mesh
// (parallel/partition.h) in local node numbers, owns the rows of its nodes (four each), and
// assembles the cells it owns; its iterate covers the piece (owned and halo nodes), refreshed
// from the distributed solution after each step.
class OseenSystem {
 public:
  OseenSystem(const HybridMesh& mesh, const parallel::NodeNumbering& numbering, MPI_Comm comm,
              const std::string& prefix, const BackflowStabilization& backflow, MatType type);

  bool owns(NodeId node) const { return numbering_.owns(node); }
  PetscInt block(NodeId node) const { return numbering_.to_global(node); }
  int rank() const { return rank_; }
  // The global rows of this rank that `bc` fixes: three per velocity node, the pinned pressure.
  std::vector<PetscInt> fixed_rows(const DirichletConditions& bc) const;

  // v's values at every node of the piece.
  void gather(Vec v, FlowField& field);

  // The field into v's rows of this rank.
  void distribute(const FlowField& field, Vec v) const;

  Mat matrix() const { return matrix_; }
  Vec rhs() const { return rhs_; }
  Vec solution() const { return solution_; }
  Vec residual() const { return residual_; }

  // Newton's whole derivative as an operator: the assembled matrix (which also preconditions
  // it) minus the reconstructed term's derivative (reconstruction_derivative.h), zero on the
  // rows fixed by Dirichlet conditions (`rows`, global).
  void use_newton_operator(const std::vector<PetscInt>& rows);
  // The operator at the advection (the iterate) and viscosity of this Newton step.
  Mat newton_operator(const std::vector<Eigen::Vector3d>& advection, double nu);

  // The lumped L2 projection of ∇a onto the nodes: G_i = Σ_K ∫ N_i ∇a / Σ_K ∫ N_i.
  void recover_gradient(const std::vector<Eigen::Vector3d>& a);

  // The velocity rows' lumped mass ∫ N_i (computed by every assembly) into v's rows of this
  // rank, 0 in the pressure rows.
  void velocity_mass(Vec v) const;

  // Pseudo-transient continuation (Kelley & Keyes 1998): adds M/Δτ to the velocity rows of the
  // matrix — not to the residual, so the converged answer is the steady one. Δτ is local,
  // CFL · h / (|a| + ν/h) with h = (∫N_i)^⅓, so every node advances at the same Courant number.
  // A finite CFL keeps the step a damped, time-like one where Newton's full step would
  // overshoot, and makes the matrix more diagonally dominant for ILU.
  void add_pseudo_time(const std::vector<Eigen::Vector3d>& advection, double nu, double cfl);

  // K(a) and F(a) for advection a (per node), ν and f; with a residual-computing linearization
  // also R = K(a)(a, p) − F(a), and for Newton K(a) plus the derivative terms.
  void assemble(const std::vector<Eigen::Vector3d>& advection, const std::vector<double>& pressure,
                double nu, const BodyForce& force, Linearization linearization);

 private:
  // Outflow stabilization (Bazilevs, Gohean, Hughes, Moser & Zhang 2009): where the flow enters
  // through the open outlet, the natural condition lets energy in and the iteration can blow
  // up; −β ∫ (a·n)₋ u·w over the outlet removes exactly that inflow of kinetic energy and is
  // zero wherever the flow leaves.
  void assemble_backflow(const std::vector<Eigen::Vector3d>& advection,
                         Linearization linearization);

  template <class Cells>
  void owned_cells(const Cells& cells, std::vector<std::size_t>& owned) const {
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (numbering_.owns_cell(cells[c])) owned.push_back(c);
  }

  template <class E, class Cells, class Force>
  void assemble_cells(const Cells& all, const std::vector<std::size_t>& owned,
                      const std::vector<Eigen::Vector3d>& advection,
                      const std::vector<double>& pressure, double nu, const Force& force,
                      Linearization linearization);

  // y = J x − B R_g x, the shell's product: each rank applies its cells' share on its piece
  // and adds it into the owners' rows, as the matrix assembly does; fixed rows keep J's.
  static PetscErrorCode newton_product(Mat shell, Vec x, Vec y);

  const HybridMesh& mesh_;
  const parallel::NodeNumbering& numbering_;
  BackflowStabilization backflow_;
  petsc::Matrix matrix_;
  std::optional<parallel::BlockAssembly> insertion_;  // the cells' matrices into matrix_
  int rank_ = 0;
  bool all_cells_ = true;  // the whole mesh on one rank: every cell, no lists
  std::vector<std::size_t> owned_tets_, owned_pyramids_, owned_hexes_;  // assembled here
  petsc::Vector rhs_, solution_, residual_, scratch_, piece_;
  petsc::Scatter gather_;
  std::vector<Eigen::Matrix<double, 1, 9>> gradient_;  // recovered ∇a per node
  std::vector<double> lumped_mass_;                    // ∫ N_i per node
  std::optional<ReconstructionDerivative> derivative_;
  petsc::Matrix newton_operator_;
  petsc::Vector operand_, product_;  // the shell's operand and product on the piece
  std::vector<char> fixed_;          // per owned row: fixed by a Dirichlet condition
};

}  // namespace naris::ns
