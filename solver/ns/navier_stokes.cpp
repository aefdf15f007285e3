#include "ns/navier_stokes.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "core/error.h"
#include "core/log.h"
#include "ns/forcing_term.h"
#include "ns/node_graph.h"
#include "ns/oseen_element.h"
#include "ns/preconditioner_reuse.h"
#include "ns/reconstruction_derivative.h"
#include "ns/segregated_step.h"
#include "parallel/block_assembly.h"
#include "parallel/partition.h"
#include "parallel/petsc.h"

namespace naris::ns {
namespace {

using petsc::check;

// The system over the ranks of `comm`: each rank holds its piece of the mesh
// (parallel/partition.h) in local node numbers, owns the rows of its nodes (four each), and
// assembles the cells it owns; its iterate covers the piece (owned and halo nodes), refreshed
// from the distributed solution after each step.
class OseenSystem {
 public:
  OseenSystem(const HybridMesh& mesh, const parallel::NodeNumbering& numbering, MPI_Comm comm,
              const std::string& prefix, int backflow_patch, double backflow_beta, MatType type)
      : mesh_(mesh),
        numbering_(numbering),
        backflow_patch_(backflow_patch),
        backflow_beta_(backflow_beta) {
    int rank = 0, size = 1;
    MPI_Comm_rank(comm, &rank);
    MPI_Comm_size(comm, &size);
    rank_ = rank;
    if (size > 1 && numbering.global.empty())
      fail("internal: {} ranks share a system without a mesh piece each", size);
    const auto n = static_cast<std::int64_t>(numbering.global_nodes);
    all_cells_ = numbering.global.empty();
    if (!all_cells_) {
      owned_cells(mesh.tets, owned_tets_);
      owned_cells(mesh.pyramids, owned_pyramids_);
      owned_cells(mesh.hexes, owned_hexes_);
    }
    const PetscInt local = numbering.owned;
    // 4×4 blocks by default (a third less memory and faster ILU); `-ns_mat_type aij` for
    // preconditioners that split the fields inside a block (fieldsplit).
    matrix_ = block_matrix(mesh, numbering, comm, type, prefix);
    // Dirichlet rows are zeroed every iteration; their pattern must survive for the next one.
    check(MatSetOption(matrix_, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE), "MatSetOption");
    check(VecCreate(comm, rhs_.out()), "VecCreate");
    check(VecSetSizes(rhs_, 4 * local, 4 * n), "VecSetSizes");
    check(VecSetBlockSize(rhs_, 4), "VecSetBlockSize");
    check(VecSetType(rhs_, VECSTANDARD), "VecSetType");
    check(VecDuplicate(rhs_, solution_.out()), "VecDuplicate");
    check(VecDuplicate(rhs_, residual_.out()), "VecDuplicate");
    check(VecDuplicate(rhs_, scratch_.out()), "VecDuplicate");
    // The iterate on the piece: the owned rows and the halo's, from whichever rank owns them.
    const auto nodes = static_cast<PetscInt>(mesh.nodes.size());
    std::vector<PetscInt> blocks(static_cast<std::size_t>(nodes));
    for (NodeId k = 0; k < nodes; ++k) blocks[static_cast<std::size_t>(k)] = numbering.to_global(k);
    petsc::IndexSet from;
    check(ISCreateBlock(PETSC_COMM_SELF, 4, nodes, blocks.data(), PETSC_COPY_VALUES, from.out()),
          "ISCreateBlock");
    check(VecCreateSeq(PETSC_COMM_SELF, 4 * nodes, piece_.out()), "VecCreateSeq");
    check(VecScatterCreate(rhs_, from, piece_, nullptr, gather_.out()), "VecScatterCreate");
    insertion_.emplace(matrix_, numbering_);
  }

  bool owns(NodeId node) const { return numbering_.owns(node); }
  PetscInt block(NodeId node) const { return numbering_.to_global(node); }
  int rank() const { return rank_; }

  // v's values at every node of the piece.
  void gather(Vec v, FlowField& field) {
    check(VecScatterBegin(gather_, v, piece_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterBegin");
    check(VecScatterEnd(gather_, v, piece_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
    const PetscScalar* x = nullptr;
    check(VecGetArrayRead(piece_, &x), "VecGetArrayRead");
    for (std::size_t k = 0; k < field.pressure.size(); ++k) {
      field.velocity[k] = {x[4 * k], x[4 * k + 1], x[4 * k + 2]};
      field.pressure[k] = x[4 * k + 3];
    }
    check(VecRestoreArrayRead(piece_, &x), "VecRestoreArrayRead");
  }

  // The field into v's rows of this rank.
  void distribute(const FlowField& field, Vec v) const {
    PetscScalar* x = nullptr;
    check(VecGetArray(v, &x), "VecGetArray");
    for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i) {
      for (int c = 0; c < 3; ++c) x[4 * i + static_cast<std::size_t>(c)] = field.velocity[i][c];
      x[4 * i + 3] = field.pressure[i];
    }
    check(VecRestoreArray(v, &x), "VecRestoreArray");
  }

  Mat matrix() const { return matrix_; }
  Vec rhs() const { return rhs_; }
  Vec solution() const { return solution_; }
  Vec residual() const { return residual_; }

  // Newton's whole derivative as an operator: the assembled matrix (which also preconditions
  // it) minus the reconstructed term's derivative (reconstruction_derivative.h), zero on the
  // rows fixed by Dirichlet conditions (`rows`, global).
  void use_newton_operator(const std::vector<PetscInt>& rows) {
    fixed_.assign(4 * static_cast<std::size_t>(numbering_.owned), 0);
    const PetscInt first = 4 * static_cast<PetscInt>(numbering_.range.first);
    for (PetscInt r : rows) fixed_[static_cast<std::size_t>(r - first)] = 1;
    PetscInt local = 0, global = 0;
    check(MatGetLocalSize(matrix_, &local, nullptr), "MatGetLocalSize");
    check(MatGetSize(matrix_, &global, nullptr), "MatGetSize");
    check(MatCreateShell(PetscObjectComm(reinterpret_cast<PetscObject>(matrix_.get())), local,
                         local, global, global, this, newton_operator_.out()),
          "MatCreateShell");
    check(MatShellSetOperation(newton_operator_, MATOP_MULT,
                               reinterpret_cast<void (*)(void)>(&OseenSystem::newton_product)),
          "MatShellSetOperation");
    check(VecDuplicate(piece_, operand_.out()), "VecDuplicate");
    check(VecDuplicate(piece_, product_.out()), "VecDuplicate");
  }
  // The operator at the advection (the iterate) and viscosity of this Newton step.
  Mat newton_operator(const std::vector<Eigen::Vector3d>& advection, double nu) {
    // Allocated at first use: most runs never take such a step.
    if (!derivative_)
      derivative_.emplace(mesh_,
                          OwnedCells{all_cells_, owned_tets_, owned_pyramids_, owned_hexes_});
    const petsc::LoggedEvent logged("NSWholeDerivative");
    derivative_->assemble(advection, nu);
    return newton_operator_;
  }

  // The lumped L2 projection of ∇a onto the nodes: G_i = Σ_K ∫ N_i ∇a / Σ_K ∫ N_i.
  void recover_gradient(const std::vector<Eigen::Vector3d>& a) {
    gradient_.assign(mesh_.nodes.size(), Eigen::Matrix<double, 1, 9>::Zero());
    std::vector<double> mass(mesh_.nodes.size(), 0.0);
    // Every cell of the piece: the gradient is needed at the nodes of owned cells, and the
    // piece holds all the cells around those.
    auto run = [&](const auto& cells, auto element) {
      using E = decltype(element);
      constexpr int N = E::nodes;
      Eigen::Matrix<double, N, 3> X, A;
      for (const auto& cell : cells) {
        for (int i = 0; i < N; ++i) {
          X.row(i) = mesh_.nodes[static_cast<std::size_t>(cell[i])].transpose();
          A.row(i) = a[static_cast<std::size_t>(cell[i])].transpose();
        }
        for (std::size_t q = 0; q < ShapeTable<E>::get().points.size(); ++q) {
          const auto m = fem::map_to_cell<E>(X, ShapeTable<E>::get().shapes[q]);
          const double w = ShapeTable<E>::get().points[q].weight * m.det_jacobian;
          const Eigen::Matrix3d g = A.transpose() * m.gradient;  // g(c, d) = ∂a_c/∂x_d
          const Eigen::Matrix<double, 1, 9> row =
              Eigen::Map<const Eigen::Matrix<double, 1, 9>>(Eigen::Matrix3d(g.transpose()).data());
          for (int i = 0; i < N; ++i) {
            const auto n = static_cast<std::size_t>(cell[i]);
            gradient_[n] += w * m.value[i] * row;
            mass[n] += w * m.value[i];
          }
        }
      }
    };
    run(mesh_.tets, fem::Tet4{});
    run(mesh_.pyramids, fem::Pyr5{});
    run(mesh_.hexes, fem::Hex8{});
    for (std::size_t n = 0; n < mass.size(); ++n)
      if (mass[n] > 0.0) gradient_[n] /= mass[n];
    lumped_mass_ = std::move(mass);
  }

  // Pseudo-transient continuation (Kelley & Keyes 1998): adds M/Δτ to the velocity rows of the
  // matrix — not to the residual, so the converged answer is the steady one. Δτ is local,
  // CFL · h / (|a| + ν/h) with h = (∫N_i)^⅓, so every node advances at the same Courant number.
  // A finite CFL keeps the step a damped, time-like one where Newton's full step would
  // overshoot, and makes the matrix more diagonally dominant for ILU.
  void add_pseudo_time(const std::vector<Eigen::Vector3d>& advection, double nu, double cfl) {
    PetscScalar* d = nullptr;
    check(VecSet(scratch_, 0.0), "VecSet");
    check(VecGetArray(scratch_, &d), "VecGetArray");
    for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i) {
      const double m = lumped_mass_[i];
      if (!(m > 0.0)) continue;
      const double h = std::cbrt(m);
      const double rate = (advection[i].norm() + nu / h) / (cfl * h);
      for (int c = 0; c < 3; ++c) d[4 * i + static_cast<std::size_t>(c)] = m * rate;
    }
    check(VecRestoreArray(scratch_, &d), "VecRestoreArray");
    check(MatDiagonalSet(matrix_, scratch_, ADD_VALUES), "MatDiagonalSet");
  }

  // K(a) and F(a) for advection a (per node), ν and f; with a residual-computing linearization
  // also R = K(a)(a, p) − F(a), and for Newton K(a) plus the derivative terms.
  void assemble(const std::vector<Eigen::Vector3d>& advection, const std::vector<double>& pressure,
                double nu, const BodyForce& force, Linearization linearization) {
    const petsc::LoggedEvent logged("NSAssembly");
    recover_gradient(advection);
    check(MatZeroEntries(matrix_), "MatZeroEntries");
    check(VecSet(rhs_, 0.0), "VecSet");
    check(VecSet(residual_, 0.0), "VecSet");
    const auto f = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
      return force ? force(x) : Eigen::Vector3d::Zero();
    };
    insertion_->begin();
    assemble_cells<fem::Tet4>(mesh_.tets, owned_tets_, advection, pressure, nu, f, linearization);
    assemble_cells<fem::Pyr5>(mesh_.pyramids, owned_pyramids_, advection, pressure, nu, f,
                              linearization);
    assemble_cells<fem::Hex8>(mesh_.hexes, owned_hexes_, advection, pressure, nu, f, linearization);
    insertion_->end();
    // The piece holds the boundary faces this rank owns.
    if (backflow_patch_ >= 0) assemble_backflow(advection, linearization);
    check(MatAssemblyBegin(matrix_, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
    check(MatAssemblyEnd(matrix_, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
    for (Vec v : {rhs_.get(), residual_.get()}) {
      check(VecAssemblyBegin(v), "VecAssemblyBegin");
      check(VecAssemblyEnd(v), "VecAssemblyEnd");
    }
  }

 private:
  // Outflow stabilization (Bazilevs, Gohean, Hughes, Moser & Zhang 2009): where the flow enters
  // through the open outlet, the natural condition lets energy in and the iteration can blow
  // up; −β ∫ (a·n)₋ u·w over the outlet removes exactly that inflow of kinetic energy and is
  // zero wherever the flow leaves.
  void assemble_backflow(const std::vector<Eigen::Vector3d>& advection,
                         Linearization linearization) {
    const bool newton = linearization == Linearization::newton;
    auto face = [&](std::span<const NodeId> v) {
      const int m = static_cast<int>(v.size());
      const auto node = [&](int i) {
        return static_cast<std::size_t>(v[static_cast<std::size_t>(i)]);
      };
      Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
      // Newton's share, d/du of the term with a = u: −β ∫ H(−u·n) (δu·n) (u·w); rows and
      // columns (4i + c) like PETSc's block.
      Eigen::Matrix<double, 16, 16> D = Eigen::Matrix<double, 16, 16>::Zero();
      // Fan triangles from v[0], three edge-midpoint points each (degree 2 on every triangle).
      for (int k = 1; k + 1 < m; ++k) {
        const int tri[3] = {0, k, k + 1};
        const Eigen::Vector3d an =
            0.5 * (mesh_.nodes[node(tri[1])] - mesh_.nodes[node(tri[0])])
                      .cross(mesh_.nodes[node(tri[2])] - mesh_.nodes[node(tri[0])]);
        const double area = an.norm();
        if (area <= 0.0) continue;
        const Eigen::Vector3d normal = an / area;
        for (int q = 0; q < 3; ++q) {
          double phi[3] = {0.5, 0.5, 0.5};
          phi[q] = 0.0;
          Eigen::Vector3d a = Eigen::Vector3d::Zero();
          for (int i = 0; i < 3; ++i) a += phi[i] * advection[node(tri[i])];
          const double inflow = std::min(0.0, a.dot(normal));
          if (inflow == 0.0) continue;
          const double weight = -backflow_beta_ * area / 3.0;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              M(tri[i], tri[j]) += weight * inflow * phi[i] * phi[j];
              if (newton)
                D.block<3, 3>(4 * tri[i], 4 * tri[j]) +=
                    weight * phi[i] * phi[j] * a * normal.transpose();
            }
        }
      }
      if (M.isZero()) return;
      // PETSc reads the (4m)×(4m) block row-major: velocity components on the block diagonal.
      std::array<double, 16 * 16> block{};
      std::array<double, 16> r{};  // M u, the term's share of the residual (u = a here)
      std::array<PetscInt, 4> ids{};
      for (int i = 0; i < m; ++i) {
        ids[static_cast<std::size_t>(i)] = this->block(v[static_cast<std::size_t>(i)]);
        for (int j = 0; j < m; ++j)
          for (int c = 0; c < 3; ++c) {
            block[static_cast<std::size_t>((4 * i + c) * 4 * m + 4 * j + c)] = M(i, j);
            r[static_cast<std::size_t>(4 * i + c)] += M(i, j) * advection[node(j)][c];
            if (newton)
              for (int d = 0; d < 3; ++d)
                block[static_cast<std::size_t>((4 * i + c) * 4 * m + 4 * j + d)] +=
                    D(4 * i + c, 4 * j + d);
          }
      }
      check(MatSetValuesBlocked(matrix_, m, ids.data(), m, ids.data(), block.data(), ADD_VALUES),
            "MatSetValuesBlocked");
      if (linearization != Linearization::picard)
        check(VecSetValuesBlocked(residual_, m, ids.data(), r.data(), ADD_VALUES),
              "VecSetValuesBlocked");
    };
    for_each_boundary_face(mesh_, [&](std::span<const NodeId> v, int patch) {
      if (patch == backflow_patch_) face(v);
    });
  }

  template <class Cells>
  void owned_cells(const Cells& cells, std::vector<std::size_t>& owned) const {
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (numbering_.owns_cell(cells[c])) owned.push_back(c);
  }

  template <class E, class Cells, class Force>
  void assemble_cells(const Cells& all, const std::vector<std::size_t>& owned,
                      const std::vector<Eigen::Vector3d>& advection,
                      const std::vector<double>& pressure, double nu, const Force& force,
                      Linearization linearization) {
    constexpr int N = E::nodes;
    Eigen::Matrix<double, N, 3> X, a;
    Eigen::Matrix<double, N, 1> p;
    Eigen::Matrix<double, N, 9> grad;
    ElementSystem<N> sys;
    std::array<PetscInt, N> blocks;
    const std::size_t count = all_cells_ ? all.size() : owned.size();
    for (std::size_t k = 0; k < count; ++k) {
      const auto& cell = all[all_cells_ ? k : owned[k]];
      for (int i = 0; i < N; ++i) {
        const auto n = static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]);
        X.row(i) = mesh_.nodes[n].transpose();
        a.row(i) = advection[n].transpose();
        grad.row(i) = gradient_[n];
        p[i] = pressure[n];
        blocks[static_cast<std::size_t>(i)] = block(cell[static_cast<std::size_t>(i)]);
      }
      oseen_element<E>(X, a, &grad, nu, force, sys, p, linearization);
      insertion_->add(std::span<const NodeId>(cell.data(), N), sys.K.data());
      check(VecSetValuesBlocked(rhs_, N, blocks.data(), sys.F.data(), ADD_VALUES),
            "VecSetValuesBlocked");
      if (linearization != Linearization::picard)
        check(VecSetValuesBlocked(residual_, N, blocks.data(), sys.R.data(), ADD_VALUES),
              "VecSetValuesBlocked");
    }
  }

  // y = J x − B R_g x, the shell's product: each rank applies its cells' share on its piece
  // and adds it into the owners' rows, as the matrix assembly does; fixed rows keep J's.
  static PetscErrorCode newton_product(Mat shell, Vec x, Vec y) {
    OseenSystem* self = nullptr;
    PetscCall(MatShellGetContext(shell, &self));
    PetscCall(MatMult(self->matrix_, x, y));
    PetscCall(VecScatterBegin(self->gather_, x, self->operand_, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(self->gather_, x, self->operand_, INSERT_VALUES, SCATTER_FORWARD));
    const PetscScalar* v = nullptr;
    PetscScalar* out = nullptr;
    PetscCall(VecGetArrayRead(self->operand_, &v));
    PetscCall(VecGetArray(self->product_, &out));
    self->derivative_->apply(v, out);
    PetscCall(PetscLogFlops(self->derivative_->apply_flops()));
    PetscCall(VecRestoreArray(self->product_, &out));
    PetscCall(VecRestoreArrayRead(self->operand_, &v));
    PetscCall(VecSet(self->scratch_, 0.0));
    PetscCall(VecScatterBegin(self->gather_, self->product_, self->scratch_, ADD_VALUES,
                              SCATTER_REVERSE));
    PetscCall(
        VecScatterEnd(self->gather_, self->product_, self->scratch_, ADD_VALUES, SCATTER_REVERSE));
    PetscCall(VecGetArray(self->scratch_, &out));
    for (std::size_t r = 0; r < self->fixed_.size(); ++r)
      if (self->fixed_[r]) out[r] = 0.0;
    PetscCall(VecRestoreArray(self->scratch_, &out));
    PetscCall(VecAXPY(y, -1.0, self->scratch_));
    return 0;
  }

  const HybridMesh& mesh_;
  const parallel::NodeNumbering& numbering_;
  int backflow_patch_ = -1;
  double backflow_beta_ = 0.0;
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

// ⟨t, v⟩ of the arclength constraint with v a vector of the system (this rank's owned rows).
double velocity_inner_product(const FlowField& t, Vec v, const parallel::NodeNumbering& numbering,
                              MPI_Comm comm) {
  const PetscScalar* x = nullptr;
  check(VecGetArrayRead(v, &x), "VecGetArrayRead");
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering.owned); ++i)
    for (int c = 0; c < 3; ++c) sum += t.velocity[i][c] * x[4 * i + static_cast<std::size_t>(c)];
  check(VecRestoreArrayRead(v, &x), "VecRestoreArrayRead");
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum / static_cast<double>(numbering.global_nodes);
}

// N(u, Re) of navier_stokes.h: how far the iterate is off the step's hyperplane.
double arclength_residual(const ArclengthConstraint& a, const FlowField& u, double reynolds,
                          const parallel::NodeNumbering& numbering, MPI_Comm comm) {
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering.owned); ++i)
    sum += a.tangent.velocity[i].dot(u.velocity[i] - a.origin.velocity[i]);
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum / static_cast<double>(numbering.global_nodes) +
         a.tangent_reynolds * (reynolds - a.origin_reynolds) /
             (a.origin_reynolds * a.origin_reynolds) -
         a.step;
}

}  // namespace

double velocity_inner_product(const FlowField& a, const FlowField& b,
                              const parallel::NodeNumbering& numbering, MPI_Comm comm) {
  double sum = 0.0;
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering.owned); ++i)
    sum += a.velocity[i].dot(b.velocity[i]);
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, comm);
  return sum / static_cast<double>(numbering.global_nodes);
}

double aim_along_secant(ArclengthConstraint& c, const FlowField& from, double re_from,
                        const FlowField& to, double re_to, const parallel::NodeNumbering& numbering,
                        MPI_Comm comm) {
  c.tangent = to;
  for (std::size_t k = 0; k < to.pressure.size(); ++k) {
    c.tangent.velocity[k] -= from.velocity[k];
    c.tangent.pressure[k] -= from.pressure[k];
  }
  c.tangent_reynolds = re_to - re_from;
  const double length = std::sqrt(velocity_inner_product(c.tangent, c.tangent, numbering, comm) +
                                  c.tangent_reynolds * c.tangent_reynolds / (re_to * re_to));
  for (std::size_t k = 0; k < to.pressure.size(); ++k) {
    c.tangent.velocity[k] /= length;
    c.tangent.pressure[k] /= length;
  }
  c.tangent_reynolds /= length;
  return length;
}

FlowField arclength_predictor(const ArclengthConstraint& c) {
  FlowField guess = c.origin;
  for (std::size_t k = 0; k < guess.pressure.size(); ++k) {
    guess.velocity[k] += c.step * c.tangent.velocity[k];
    guess.pressure[k] += c.step * c.tangent.pressure[k];
  }
  return guess;
}

FlowField solve_navier_stokes(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                              double nu, const BodyForce& force, const DirichletConditions& bc,
                              const PicardOptions& options, PicardReport* report,
                              const FlowField* initial, const ArclengthConstraint* arclength) {
  if (!(nu > 0.0) || !std::isfinite(nu)) fail("viscosity must be positive and finite (got {})", nu);
  if (arclength && (!initial || !options.newton || options.pseudo_cfl > 0.0 ||
                    options.scheme != PicardOptions::Scheme::coupled))
    fail("internal: an arclength step needs a predicted field and coupled Newton steps");
  if (bc.nodes.size() != bc.values.size())
    fail("Dirichlet conditions: {} nodes but {} values", bc.nodes.size(), bc.values.size());
  const std::size_t n = mesh.nodes.size();
  FlowField field{std::vector<Eigen::Vector3d>(n, Eigen::Vector3d::Zero()),
                  std::vector<double>(n, 0.0)};
  if (initial) field = *initial;
  const MPI_Comm comm =
      options.communicator == MPI_COMM_NULL ? PETSC_COMM_WORLD : options.communicator;
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);
  using Scheme = PicardOptions::Scheme;
  const bool segregated = options.scheme == Scheme::segregated;
  // The segregated sweep takes the velocity and pressure blocks out: scalar (AIJ) storage.
  OseenSystem system(mesh, numbering, comm, options.options_prefix, options.backflow_patch,
                     options.backflow_beta, options.scheme == Scheme::coupled ? MATBAIJ : MATAIJ);
  std::optional<SegregatedStep> sweep;
  if (segregated)
    sweep.emplace(system.matrix(), options.options_prefix, options.velocity_relaxation,
                  options.pressure_relaxation);
  if (options.scheme == Scheme::segregated_krylov)
    sweep.emplace(system.matrix(), options.options_prefix, 1.0, 1.0, true);
  // Fixed rows, those of this rank: three per velocity node, one for the pinned pressure.
  std::vector<PetscInt> rows;
  for (std::size_t k = 0; k < bc.nodes.size(); ++k) {
    field.velocity[static_cast<std::size_t>(bc.nodes[k])] = bc.values[k];
    if (system.owns(bc.nodes[k]))
      for (int c = 0; c < 3; ++c) rows.push_back(4 * system.block(bc.nodes[k]) + c);
  }
  if (bc.pressure_pin) {
    field.pressure[static_cast<std::size_t>(bc.pressure_pin->first)] = bc.pressure_pin->second;
    if (system.owns(bc.pressure_pin->first))
      rows.push_back(4 * system.block(bc.pressure_pin->first) + 3);
  }

  if (options.scheme == Scheme::coupled && options.newton) system.use_newton_operator(rows);

  petsc::LinearSolver ksp;
  check(KSPCreate(comm, ksp.out()), "KSPCreate");
  check(KSPSetOptionsPrefix(ksp, options.options_prefix.c_str()), "KSPSetOptionsPrefix");
  // GMRES on ILU(1) of the 4×4-block matrix in reverse Cuthill–McKee order: on the 89 k-cell
  // phantom at Re 300, 56 iterations where ILU(0) in mesh order needs 231, 3× faster per step
  // (ILU(2) halves the iterations again but not the time). Each solve is inexact: it stops
  // when the residual of the correction equation has fallen by the forcing term
  // (forcing_term.h, at least `linear_tolerance`) — the outer iteration measures the true
  // residual and corrects what is left.
  // `-ns_ksp_type preonly -ns_pc_type lu` gives a direct solve.
  check(KSPSetType(ksp, KSPGMRES), "KSPSetType");
  check(KSPGMRESSetRestart(ksp, 200), "KSPGMRESSetRestart");
  // Right preconditioning: GMRES then minimizes the true residual, which is what the tolerance
  // is meant for. With ILU on the neonatal airway's saddle-point matrix the left-preconditioned
  // norm fell 1e-3 while the true one did not, and the "correction" raised the nonlinear
  // residual even at 1/64 of a step.
  check(KSPSetPCSide(ksp, PC_RIGHT), "KSPSetPCSide");
  check(KSPSetTolerances(ksp, options.linear_tolerance, 1e-30, PETSC_DEFAULT, 5000),
        "KSPSetTolerances");
  PC pc = nullptr;
  check(KSPGetPC(ksp, &pc), "KSPGetPC");
  if (options.scheme == Scheme::segregated_krylov) {
    sweep->use_as_preconditioner(pc);
  } else if (ranks == 1) {
    check(PCSetType(pc, PCILU), "PCSetType");
    check(PCFactorSetLevels(pc, 1), "PCFactorSetLevels");
    check(PCFactorSetMatOrderingType(pc, MATORDERINGRCM), "PCFactorSetMatOrderingType");
  } else {
    // On several ranks, additive Schwarz with one layer of overlap and the same ILU(1) in RCM
    // order on each rank's block. On the neonate from Re 50 to 300 on two ranks, block Jacobi
    // (no overlap) took 9881 GMRES iterations (one rank: 8099) and 864 s; the overlap, 8536 and
    // 729 s, for 19 % more memory per rank. Defaults in the options database, so that the
    // command line still overrides them (`-ns_pc_type bjacobi` for the leaner one).
    check(PCSetType(pc, PCASM), "PCSetType");
    check(PCASMSetOverlap(pc, 1), "PCASMSetOverlap");
    for (const auto& [name, value] :
         {std::pair{"sub_pc_type", "ilu"}, std::pair{"sub_pc_factor_levels", "1"},
          std::pair{"sub_pc_factor_mat_ordering_type", "rcm"}}) {
      const std::string key = "-" + options.options_prefix + name;
      PetscBool set = PETSC_FALSE;
      check(PetscOptionsHasName(nullptr, nullptr, key.c_str(), &set), "PetscOptionsHasName");
      if (!set) check(PetscOptionsSetValue(nullptr, key.c_str(), value), "PetscOptionsSetValue");
    }
  }
  // A line now and then from a long linear solve, which otherwise runs silent for minutes.
  struct LinearProgress {
    Stopwatch clock;
    double interval = 0.0, last = 0.0, start_norm = 0.0;
  } progress{Stopwatch(), options.progress_seconds};
  if (options.progress_seconds > 0.0) {
    auto monitor = [](KSP solver, PetscInt it, PetscReal norm, void* context) -> PetscErrorCode {
      auto& p = *static_cast<LinearProgress*>(context);
      if (it == 0) {
        p = {Stopwatch(), p.interval, 0.0, norm};
        return 0;
      }
      const double now = p.clock.seconds();
      if (now - p.last < p.interval) return 0;
      p.last = now;
      KSPType type = nullptr;
      PetscCall(KSPGetType(solver, &type));
      log_line(fmt::format("      {} {:5d}: residual {:.2e} of the solve's first, {:.0f} s", type,
                           static_cast<int>(it), norm / p.start_norm, now));
      return 0;
    };
    check(KSPMonitorSet(ksp, monitor, &progress, nullptr), "KSPMonitorSet");
  }
  check(KSPSetFromOptions(ksp), "KSPSetFromOptions");
  // As set, by default or from the command line: the tightest relative tolerance and the
  // iteration limit.
  PetscReal tightest_linear_tolerance = 0.0;
  PetscInt max_linear_iterations = 0;
  check(KSPGetTolerances(ksp, &tightest_linear_tolerance, nullptr, nullptr, &max_linear_iterations),
        "KSPGetTolerances");

  // Any preconditioner of the coupled system may be kept; the segregated sweeps set theirs up
  // themselves.
  PreconditionerReuse reuse(options.reuse_preconditioner && options.scheme == Scheme::coupled);
  PicardReport local;
  PicardReport& r = report ? *report : local;
  r = {};
  petsc::Vector current, product;
  check(VecDuplicate(system.solution(), current.out()), "VecDuplicate");
  check(VecDuplicate(system.solution(), product.out()), "VecDuplicate");
  // Stokes first (a = 0) unless warm-started; then Picard on a = u, then Newton.
  bool stokes = initial == nullptr;
  // Damped steps: the update U ← U + ω (U* − U) starts at the given relaxation; when the
  // residual grows, ω is halved and the step retaken from the previous iterate (no new solve) —
  // a backtracking line search; after a step that halves the residual, or three steps that lower
  // it, ω grows back towards the given value. Newton takes over after `picard_steps` Picard
  // steps and hands back to Picard when its step had to be cut below 1/8 (far from the
  // solution, where Picard's contraction is the more robust).
  double omega = options.relaxation, previous_norm = INFINITY;
  FlowField previous, target;  // the iterate a step started from, and the solve's answer
  // With an arclength constraint Re moves with the field (relaxed alike): the Re of the
  // iterate, of the step's start and of the solve's answer.
  double reynolds = 1.0 / nu, previous_reynolds = reynolds, target_reynolds = reynolds;
  auto relax = [&] {
    for (std::size_t k = 0; k < n; ++k) {
      field.velocity[k] =
          previous.velocity[k] + omega * (target.velocity[k] - previous.velocity[k]);
      field.pressure[k] =
          previous.pressure[k] + omega * (target.pressure[k] - previous.pressure[k]);
    }
    if (arclength) {
      reynolds = previous_reynolds + omega * (target_reynolds - previous_reynolds);
      nu = 1.0 / reynolds;
    }
  };
  const std::vector<double> zeros(rows.size(), 0.0);
  double cfl = INFINITY, eta = tightest_linear_tolerance;  // eta: the linear solve's tolerance
  int solves = 0, decreasing = 0, picard_run = 0;
  // ∂R/∂Re by a forward difference, and the second solve's answer b, in their own vectors.
  petsc::Vector sensitivity, sensitivity_solution;
  bool tangent_known = false;  // the last bordered solve's b is du/dRe
  if (arclength) {
    check(VecDuplicate(system.solution(), sensitivity.out()), "VecDuplicate");
    check(VecDuplicate(system.solution(), sensitivity_solution.out()), "VecDuplicate");
    picard_run = options.picard_steps;  // the predictor is close: Newton from the first step
  }
  bool newton_step = false;  // the kind of the last solve
  Stopwatch solve_clock;
  double last_line = 0.0;  // when the last step's line was printed, s into the solve
  for (int it = 0; solves <= options.max_iterations + 1 && it < 4 * options.max_iterations + 8;
       ++it) {
    system.distribute(field, current);
    const bool newton =
        !stokes && options.newton && !segregated && picard_run >= options.picard_steps;
    const auto linearization =
        stokes ? Linearization::picard
               : (newton ? Linearization::newton : Linearization::picard_residual);
    // R at a slightly larger Re first (the assembly below overwrites the matrix): relative
    // 1e-6, where the difference quotient of a residual smooth in ν is accurate to ~1e-6 and
    // rounding costs ~1e-10.
    constexpr double kReynoldsDifference = 1e-6;
    if (arclength) {
      system.assemble(field.velocity, field.pressure, 1.0 / (reynolds * (1 + kReynoldsDifference)),
                      force, Linearization::picard_residual);
      check(VecCopy(system.residual(), sensitivity), "VecCopy");
    }
    system.assemble(
        stokes ? std::vector<Eigen::Vector3d>(n, Eigen::Vector3d::Zero()) : field.velocity,
        field.pressure, nu, force, linearization);
    double norm = 0.0;
    bool pseudo_step = false;  // the matrix holds a pseudo-time term
    if (!stokes) {
      // The nonlinear residual K(u)u − F(u) at the current iterate; fixed rows hold exactly.
      check(VecSetValues(system.residual(), static_cast<PetscInt>(rows.size()), rows.data(),
                         zeros.data(), INSERT_VALUES),
            "VecSetValues");
      check(VecAssemblyBegin(system.residual()), "VecAssemblyBegin");
      check(VecAssemblyEnd(system.residual()), "VecAssemblyEnd");
      check(VecNorm(system.residual(), NORM_2, &norm), "VecNorm");
      if (arclength) {
        // ∂R/∂Re, zero on the fixed rows like R.
        check(VecAXPBY(sensitivity, -1.0 / (reynolds * kReynoldsDifference),
                       1.0 / (reynolds * kReynoldsDifference), system.residual()),
              "VecAXPBY");
        check(VecSetValues(sensitivity, static_cast<PetscInt>(rows.size()), rows.data(),
                           zeros.data(), INSERT_VALUES),
              "VecSetValues");
        check(VecAssemblyBegin(sensitivity), "VecAssemblyBegin");
        check(VecAssemblyEnd(sensitivity), "VecAssemblyEnd");
      }
      // Switched evolution relaxation: the Courant number follows the residual's fall, so the
      // steps turn into Newton's (or Picard's) as the iteration converges — as the square of
      // the ratio (on the neonatal airway from Re 150 to 300 with a fixed linear tolerance, 36
      // steps where the ratio itself took 42) but at most 4× a step: at Re 400 there a
      // residual that dipped for one step raised the CFL 10× and the next step blew the
      // residual up 20×. It never drops below a tenth of the first.
      if (options.pseudo_cfl > 0.0 && norm > 0.0) {
        const double fall = previous_norm / norm;
        cfl = std::isfinite(previous_norm) ? std::clamp(cfl * fall * fall, 0.1 * options.pseudo_cfl,
                                                        std::min(4.0 * cfl, 1e12))
                                           : options.pseudo_cfl;
        pseudo_step = cfl < 1e8;
        if (pseudo_step) system.add_pseudo_time(field.velocity, nu, cfl);
      }
    }
    check(MatZeroRows(system.matrix(), static_cast<PetscInt>(rows.size()), rows.data(), 1.0,
                      current, system.rhs()),
          "MatZeroRows");
    if (!stokes) {
      double load = 0.0;
      check(VecNorm(system.rhs(), NORM_2, &load), "VecNorm");
      // Relative to the load (forces and boundary data): an iterate that starts close, as a
      // warm start does, must not be held to a fraction of its own small first residual.
      // A damped step leaves part of the (linear) arclength constraint unmet: one step more.
      const bool on_constraint =
          !arclength || std::abs(arclength_residual(*arclength, field, reynolds, numbering,
                                                    comm)) <= 1e-6 * std::abs(arclength->step);
      if ((norm <= options.absolute_tolerance || norm <= options.tolerance * load) &&
          on_constraint) {
        r.residuals.push_back(norm);
        r.converged = true;
        if (arclength && tangent_known) {
          // The tangent from b = du/dRe (J b = −∂R/∂Re), not from the secant through two
          // points: points converged to 1e-5 carry errors as large as a short step near the
          // neonate's Re 467, where the secant through them reversed and a turn was claimed
          // on a branch whose Δp(Re) stayed straight.
          r.tangent = field;
          system.gather(sensitivity_solution, r.tangent);
          double length = std::sqrt(velocity_inner_product(r.tangent, r.tangent, numbering, comm) +
                                    1.0 / (reynolds * reynolds));
          if (velocity_inner_product(r.tangent, arclength->tangent, numbering, comm) +
                  arclength->tangent_reynolds / (reynolds * reynolds) <
              0.0)
            length = -length;
          for (std::size_t k = 0; k < n; ++k) {
            r.tangent.velocity[k] /= length;
            r.tangent.pressure[k] /= length;
          }
          r.tangent_reynolds = 1.0 / length;
        }
        break;
      }
      // Under pseudo-time every step is taken: a transient may have to raise the residual on
      // its way (a jet switching walls), and the falling CFL is the damping.
      if (!(norm < previous_norm) && !previous.pressure.empty() && omega > 1.0 / 64 &&
          !(options.pseudo_cfl > 0.0)) {
        omega *= 0.5;
        if (newton_step && omega < 0.125) picard_run = 0;
        relax();
        continue;
      }
      if (!std::isfinite(norm)) fail("the nonlinear iteration diverged (residual {})", norm);
      r.residuals.push_back(norm);
      // Grow ω back after a Newton step that lowered the residual (its full step is the one
      // to try first), a halving of the residual, or three decreasing steps in a row.
      decreasing = norm < previous_norm ? decreasing + 1 : 0;
      if (norm < 0.5 * previous_norm || decreasing >= 3 || (newton_step && decreasing > 0)) {
        omega = std::min(options.relaxation, 2.0 * omega);
        decreasing = 0;
      }
      eta = forcing_term(norm, previous_norm, eta, tightest_linear_tolerance,
                         options.loosest_linear_tolerance);
      previous_norm = norm;
      if (solves > options.max_iterations) break;
      const auto& history = r.residuals;
      const auto window = static_cast<std::size_t>(options.stall_steps);
      if (window > 0 && history.size() > window &&
          history.back() > 0.5 * history[history.size() - 1 - window])
        break;
    }
    // Solve for the correction δ = U* − U from a zero guess, so that the linear tolerance is
    // relative to the current nonlinear residual (an inexact Newton/Picard step): J δ = −R
    // with Newton's J or Picard's K(a) (R = K(u)U − F(u) for both). The pseudo-time term
    // changes the matrix only. The first Stokes solve corrects the boundary data: K δ = F − K U.
    // Fixed rows have a zero residual, so δ = 0 there.
    if (!stokes) {
      check(VecAXPBY(system.rhs(), -1.0, 0.0, system.residual()), "VecAXPBY");
    } else {
      check(MatMult(system.matrix(), current, product), "MatMult");
      check(VecAXPY(system.rhs(), -1.0, product), "VecAXPY");
    }
    KSPConvergedReason reason = KSP_CONVERGED_ITERATING;
    std::string linear;
    if (segregated) {
      sweep->apply(system.matrix(), system.rhs(), system.solution());
      linear = fmt::format("{} momentum and {} pressure iterations", sweep->momentum_iterations(),
                           sweep->pressure_iterations());
    } else {
      const auto kind = stokes   ? LinearProblem::stokes
                        : newton ? LinearProblem::newton
                                 : LinearProblem::picard;
      PetscInt its = 0, abandoned = 0;  // abandoned: those of a kept preconditioner's try
      // Newton's step on the coupled system solves with the whole derivative, preconditioned by
      // the assembled part — but not a pseudo-time step: on the neonatal airway from Re 125 to
      // 237.5, pseudo-time steps with the whole derivative diverged (residual 4e33 after 44
      // steps) where with the assembled part alone they converged in 39. That divergence is
      // not the derivative's alone: on two ranks, from a Re 125 field converged to 1e-4 only,
      // the assembled part alone diverged there too (residual 1e33 after 59 steps).
      const bool exact = newton && !pseudo_step && options.scheme == Scheme::coupled;
      const Mat whole_derivative = exact ? system.newton_operator(field.velocity, nu) : nullptr;
      // The reduction asked for (the first, Stokes, solve's is the tightest).
      const double decades = -std::log10(eta);
      bool rebuilt = false;
      // A solve that fails or runs over its budget with a kept preconditioner is retried with a
      // fresh one; a failure with a fresh one is the linear solver's.
      for (bool rebuild = !reuse.keeps(kind);; rebuild = true) {
        check(KSPSetOperators(ksp, exact ? whole_derivative : system.matrix(), system.matrix()),
              "KSPSetOperators");
        check(KSPSetReusePreconditioner(ksp, rebuild ? PETSC_FALSE : PETSC_TRUE),
              "KSPSetReusePreconditioner");
        check(KSPSetTolerances(ksp, eta, PETSC_DEFAULT, PETSC_DEFAULT,
                               rebuild ? max_linear_iterations
                                       : std::min<PetscInt>(max_linear_iterations,
                                                            reuse.iteration_budget(decades))),
              "KSPSetTolerances");
        // The work of the factorization and of the solve in floating-point operations as
        // PETSc counts them, not in seconds: counts are the same on every run, so whether a
        // preconditioner is kept, and with it the path of the iteration, does not depend on
        // the machine's load. (Timed, two runs of the neonate's Re 237.5 step parted at the
        // fifth Newton step and took 38 and 47 steps.) The factorization and the Krylov
        // iterations run at much the same rate (3.9–6.3 Gflop/s there), so the counts weigh them
        // as time would.
        PetscLogDouble start = 0.0, set_up = 0.0, solved = 0.0;
        check(PetscGetFlops(&start), "PetscGetFlops");
        check(KSPSetUp(ksp), "KSPSetUp");  // the factorization, when it is rebuilt
        // Additive Schwarz factors its blocks here; otherwise inside the first solve.
        check(KSPSetUpOnBlocks(ksp), "KSPSetUpOnBlocks");
        check(PetscGetFlops(&set_up), "PetscGetFlops");
        check(KSPSolve(ksp, system.rhs(), system.solution()), "KSPSolve");
        check(PetscGetFlops(&solved), "PetscGetFlops");
        check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
        check(KSPGetIterationNumber(ksp, &its), "KSPGetIterationNumber");
        r.linear_iterations += static_cast<int>(its);
        // The ranks' shares differ; they must still decide alike.
        double work[2] = {set_up - start, solved - set_up};
        MPI_Allreduce(MPI_IN_PLACE, work, 2, MPI_DOUBLE, MPI_MAX, comm);
        if (rebuild) {
          reuse.built(kind, work[0], work[1], static_cast<int>(its), decades);
          ++r.preconditioner_builds;
          rebuilt = true;
        } else {
          reuse.kept(work[1], static_cast<int>(its), decades);
          abandoned = its;
        }
        if (reason >= 0 || rebuild) break;
        reuse.abandoned();
      }
      linear = fmt::format("{} linear iterations{}", its,
                           !rebuilt ? " (preconditioner kept)"
                           : abandoned > 0
                               ? fmt::format(" (after {} with the kept preconditioner)", abandoned)
                               : "");
    }
    double reynolds_step = 0.0;
    if (arclength && !stokes) {
      // The second solve of the bordered step, J b = −∂R/∂Re, with the same preconditioner.
      check(VecAXPBY(system.rhs(), -1.0, 0.0, sensitivity), "VecAXPBY");
      check(KSPSetReusePreconditioner(ksp, PETSC_TRUE), "KSPSetReusePreconditioner");
      check(KSPSetTolerances(ksp, eta, PETSC_DEFAULT, PETSC_DEFAULT, max_linear_iterations),
            "KSPSetTolerances");
      check(KSPSolve(ksp, system.rhs(), sensitivity_solution), "KSPSolve");
      // b = du/dRe only with Newton's derivative; after a Picard step it is not the tangent.
      tangent_known = newton;
      PetscInt its = 0;
      check(KSPGetIterationNumber(ksp, &its), "KSPGetIterationNumber");
      check(KSPGetConvergedReason(ksp, &reason), "KSPGetConvergedReason");
      r.linear_iterations += static_cast<int>(its);
      linear += fmt::format(" + {} for ∂R/∂Re", its);
      // δRe from the constraint, which is linear: N + ⟨t, a + δRe b⟩ + t_Re δRe / Re₁² = 0.
      const double n_now = arclength_residual(*arclength, field, reynolds, numbering, comm);
      const double ta = velocity_inner_product(arclength->tangent, system.solution(), numbering,
                                               comm),
                   tb = velocity_inner_product(arclength->tangent, sensitivity_solution, numbering,
                                               comm);
      const double weight = 1.0 / (arclength->origin_reynolds * arclength->origin_reynolds);
      reynolds_step = -(n_now + ta) / (weight * arclength->tangent_reynolds + tb);
      check(VecAXPY(system.solution(), reynolds_step, sensitivity_solution), "VecAXPY");
    }
    check(VecAYPX(system.solution(), 1.0, current), "VecAYPX");
    ++solves;
    const bool progress_due = options.progress_seconds > 0.0 &&
                              solve_clock.seconds() - last_line >= options.progress_seconds;
    if (progress_due) last_line = solve_clock.seconds();
    if ((options.log_iterations || progress_due) && system.rank() == 0)
      log_line(fmt::format(
          "    {} {:3d}: {}, relaxation {:.3f}, CFL {:.3g}, {}{}", newton ? "Newton" : "Picard",
          solves,
          // The Stokes start has no residual before it: its solve is the first iterate.
          stokes ? std::string("Stokes start") : fmt::format("residual {:.3e}", previous_norm),
          stokes ? 1.0 : omega, stokes ? INFINITY : cfl, linear,
          arclength ? fmt::format(", Re {:.4f} → {:.4f}", reynolds, reynolds + reynolds_step)
                    : ""));
    if (reason < 0) fail("the linear solver failed ({})", KSPConvergedReasons[reason]);
    if (stokes) {
      system.gather(system.solution(), field);
    } else {
      previous = field;
      target = field;
      system.gather(system.solution(), target);
      previous_reynolds = reynolds;
      target_reynolds = reynolds + reynolds_step;
      relax();
      ++r.iterations;
      if (!newton) ++picard_run;
    }
    newton_step = newton;
    stokes = false;
  }
  r.reynolds = reynolds;
  return field;
}

FlowField solve_navier_stokes(const HybridMesh& mesh, double nu, const BodyForce& force,
                              const DirichletConditions& bc, const PicardOptions& options,
                              PicardReport* report, const FlowField* initial) {
  const MPI_Comm comm =
      options.communicator == MPI_COMM_NULL ? PETSC_COMM_WORLD : options.communicator;
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  if (ranks == 1)
    return solve_navier_stokes(mesh, parallel::whole_numbering(mesh.nodes.size()), nu, force, bc,
                               options, report, initial);
  const parallel::MeshPiece piece = parallel::mesh_piece(mesh, rank, ranks);
  std::optional<FlowField> start;
  if (initial) start = local_field(*initial, piece.numbering);
  const FlowField local = solve_navier_stokes(piece.mesh, piece.numbering, nu, force,
                                              local_conditions(bc, piece.numbering), options,
                                              report, start ? &*start : nullptr);
  return gather_field(local, piece.numbering, comm);
}

FlowField local_field(const FlowField& whole, const parallel::NodeNumbering& numbering) {
  if (whole.pressure.size() != numbering.global_nodes)
    fail("a field of {} nodes on a mesh of {}", whole.pressure.size(), numbering.global_nodes);
  const std::size_t n = numbering.global.empty() ? numbering.global_nodes : numbering.global.size();
  FlowField f{std::vector<Eigen::Vector3d>(n), std::vector<double>(n)};
  for (std::size_t k = 0; k < n; ++k) {
    const auto g = static_cast<std::size_t>(numbering.to_global(static_cast<NodeId>(k)));
    f.velocity[k] = whole.velocity[g];
    f.pressure[k] = whole.pressure[g];
  }
  return f;
}

DirichletConditions local_conditions(const DirichletConditions& whole,
                                     const parallel::NodeNumbering& numbering) {
  DirichletConditions local;
  for (std::size_t k = 0; k < whole.nodes.size(); ++k)
    if (const NodeId l = numbering.to_local(whole.nodes[k]); l >= 0) {
      local.nodes.push_back(l);
      local.values.push_back(whole.values[k]);
    }
  if (whole.pressure_pin)
    if (const NodeId l = numbering.to_local(whole.pressure_pin->first); l >= 0)
      local.pressure_pin = {l, whole.pressure_pin->second};
  return local;
}

FlowField gather_field(const FlowField& local, const parallel::NodeNumbering& numbering,
                       MPI_Comm comm, int root) {
  int rank = 0, ranks = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &ranks);
  // Four values per node, owned nodes in global order: the ranks' ranges tile the whole.
  const auto owned = static_cast<std::size_t>(numbering.owned);
  std::vector<double> mine(4 * owned);
  for (std::size_t k = 0; k < owned; ++k) {
    for (int c = 0; c < 3; ++c) mine[4 * k + static_cast<std::size_t>(c)] = local.velocity[k][c];
    mine[4 * k + 3] = local.pressure[k];
  }
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(counts.size());
  for (int r = 0; r < ranks; ++r) {
    const auto range = parallel::owned_nodes(numbering.global_nodes, r, ranks);
    counts[static_cast<std::size_t>(r)] = 4 * (range.end - range.first);
    offsets[static_cast<std::size_t>(r)] = 4 * range.first;
  }
  const bool receives = root < 0 || rank == root;
  std::vector<double> all(receives ? 4 * numbering.global_nodes : 0);
  const int count = static_cast<int>(mine.size());
  if (root < 0)
    MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                   MPI_DOUBLE, comm);
  else
    MPI_Gatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                MPI_DOUBLE, root, comm);
  FlowField whole;
  if (!receives) return whole;
  whole.velocity.resize(numbering.global_nodes);
  whole.pressure.resize(numbering.global_nodes);
  for (std::size_t k = 0; k < numbering.global_nodes; ++k) {
    whole.velocity[k] = {all[4 * k], all[4 * k + 1], all[4 * k + 2]};
    whole.pressure[k] = all[4 * k + 3];
  }
  return whole;
}

}  // namespace naris::ns
