#pragma once
// The part of Newton's derivative that the assembled matrix leaves out: that of the
// reconstructed viscous term ν ∇·(Σ_j N_j G_j) in the SUPG/PSPG residual (oseen_element.h),
// through the recovered nodal gradient G_j = (1/m_j) Σ_K ∫_K N_j ∇u. G_j depends on the
// velocity of every node around j, so the derivative couples nodes two cells apart; adding it
// to the matrix would widen the stencil ILU factors. Instead it is the product of two sparse
// operators on the node graph, applied beside the matrix inside the Krylov solver:
//
//   dR = J δ − B (R_g δ),   (R_g δ)_j = ∇δ recovered at node j (per edge j–l: (1/m_j) ∫ N_j ∇N_l),
//   (B g)_(i,c) = Σ_K ∫ τ_M ν (a·∇N_i) Σ_j ∇N_j · g_j,c     (SUPG rows)
//   (B g)_(i,p) = Σ_K ∫ τ_M ν Σ_c ∂_c N_i Σ_j ∇N_j · g_j,c   (PSPG rows)
//
// 15 numbers per edge of the node graph (J has 16), stored in single precision. Newton steps
// without pseudo-time use it (navier_stokes_solver.cpp): with it Newton converges
// quadratically, where with the term lagged the residual crawls
// (docs/results/solver-choices.md).
#include <Eigen/Dense>
#include <cstddef>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/node_graph.h"

namespace naris::ns {

// Which cells of a piece this rank assembles (its own, as for the matrix): all of them, or
// the listed ones per cell type.
struct OwnedCells {
  bool all = true;
  std::vector<std::size_t> tets, pyramids, hexes;
};

class ReconstructionDerivative {
 public:
  // The node graph of a mesh piece and R_g, which depends on the geometry only, from every
  // cell of the piece: it holds every cell around the nodes of the owned cells, so the
  // recovered gradient is complete there.
  ReconstructionDerivative(const HybridMesh& piece, OwnedCells owned);

  // B at the advection field a (one vector per piece node) and viscosity ν, from the owned
  // cells (rows of any piece node, which the caller adds into their owners' rows as for the
  // assembled matrix).
  void assemble(const std::vector<Eigen::Vector3d>& a, double nu);

  // out = B R_g v, the owned cells' share, on every piece node (four values per node,
  // interleaved u, v, w, p); v holds four values per piece node.
  void apply(const double* v, double* out);
  // The floating-point operations of one apply (18 per edge for R_g, 36 for B), for PETSc's
  // count.
  double apply_flops() const { return 54.0 * static_cast<double>(graph_.column.size()); }

 private:
  template <class E, class Cells>
  void recovery_cells(const Cells& cells, std::vector<double>& mass);
  template <class E, class Cells>
  void assemble_cells(const Cells& cells, const std::vector<std::size_t>& owned,
                      const std::vector<Eigen::Vector3d>& a, double nu);
  std::size_t edge(NodeId row, NodeId column) const;

  const HybridMesh& mesh_;
  OwnedCells owned_;
  NodeGraph graph_;  // of every piece node; its edges index the coefficients
  // The coefficients in single precision, half the memory of double (seven digits of a term
  // of the operator are below any tolerance its linear solves are given;
  // docs/results/solver-choices.md).
  std::vector<float> recovery_;   // 3 per edge: (1/m_j) ∫ N_j ∂_d N_l
  std::vector<float> supg_;       // 3 per edge
  std::vector<float> pspg_;       // 9 per edge: (c, d) row-major
  std::vector<double> gradient_;  // 9 per piece node: the recovered ∇v, (c, d) row-major
};

}  // namespace naris::ns
