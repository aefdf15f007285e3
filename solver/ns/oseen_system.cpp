#include "solver/ns/oseen_system.h"

#include <array>
#include <cmath>

#include "core/error.h"
#include "solver/ns/backflow.h"
#include "solver/ns/node_graph.h"
#include "solver/ns/recovered_gradient.h"

namespace naris::ns {

OseenSystem::OseenSystem(const HybridMesh& mesh, const parallel::NodeNumbering& numbering,
                         MPI_Comm comm, const std::string& prefix,
                         const BackflowStabilization& backflow, MatType type)
    : mesh_(mesh), numbering_(numbering), backflow_(backflow) {
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
  // 4×4 blocks by default (less memory and faster ILU than scalar storage;
  // docs/results/solver-choices.md); `-ns_mat_type aij` for preconditioners that split the
  // fields inside a block (fieldsplit).
  matrix_ = block_matrix(mesh, numbering, comm, type, prefix);
  // Dirichlet rows are zeroed every iteration; their pattern must survive for the next one.
  petsc::check(MatSetOption(matrix_, MAT_KEEP_NONZERO_PATTERN, PETSC_TRUE), "MatSetOption");
  petsc::check(VecCreate(comm, rhs_.out()), "VecCreate");
  petsc::check(VecSetSizes(rhs_, 4 * local, 4 * n), "VecSetSizes");
  petsc::check(VecSetBlockSize(rhs_, 4), "VecSetBlockSize");
  petsc::check(VecSetType(rhs_, VECSTANDARD), "VecSetType");
  petsc::check(VecDuplicate(rhs_, solution_.out()), "VecDuplicate");
  petsc::check(VecDuplicate(rhs_, residual_.out()), "VecDuplicate");
  petsc::check(VecDuplicate(rhs_, scratch_.out()), "VecDuplicate");
  // The iterate on the piece: the owned rows and the halo's, from whichever rank owns them.
  const auto nodes = static_cast<PetscInt>(mesh.nodes.size());
  std::vector<PetscInt> blocks(static_cast<std::size_t>(nodes));
  for (NodeId k = 0; k < nodes; ++k) blocks[static_cast<std::size_t>(k)] = numbering.to_global(k);
  petsc::IndexSet from;
  petsc::check(
      ISCreateBlock(PETSC_COMM_SELF, 4, nodes, blocks.data(), PETSC_COPY_VALUES, from.out()),
      "ISCreateBlock");
  petsc::check(VecCreateSeq(PETSC_COMM_SELF, 4 * nodes, piece_.out()), "VecCreateSeq");
  petsc::check(VecScatterCreate(rhs_, from, piece_, nullptr, gather_.out()), "VecScatterCreate");
  insertion_.emplace(matrix_, numbering_);
}

std::vector<PetscInt> OseenSystem::fixed_rows(const DirichletConditions& bc) const {
  std::vector<PetscInt> rows;
  for (const NodeId node : bc.nodes)
    if (owns(node))
      for (int c = 0; c < 3; ++c) rows.push_back(4 * block(node) + c);
  if (bc.pressure_pin && owns(bc.pressure_pin->first))
    rows.push_back(4 * block(bc.pressure_pin->first) + 3);
  return rows;
}

void OseenSystem::gather(Vec v, FlowField& field) {
  petsc::check(VecScatterBegin(gather_, v, piece_, INSERT_VALUES, SCATTER_FORWARD),
               "VecScatterBegin");
  petsc::check(VecScatterEnd(gather_, v, piece_, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* x = nullptr;
  petsc::check(VecGetArrayRead(piece_, &x), "VecGetArrayRead");
  for (std::size_t k = 0; k < field.pressure.size(); ++k) {
    field.velocity[k] = {x[4 * k], x[4 * k + 1], x[4 * k + 2]};
    field.pressure[k] = x[4 * k + 3];
  }
  petsc::check(VecRestoreArrayRead(piece_, &x), "VecRestoreArrayRead");
}

void OseenSystem::distribute(const FlowField& field, Vec v) const {
  PetscScalar* x = nullptr;
  petsc::check(VecGetArray(v, &x), "VecGetArray");
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i) {
    for (int c = 0; c < 3; ++c) x[4 * i + static_cast<std::size_t>(c)] = field.velocity[i][c];
    x[4 * i + 3] = field.pressure[i];
  }
  petsc::check(VecRestoreArray(v, &x), "VecRestoreArray");
}

void OseenSystem::use_newton_operator(const std::vector<PetscInt>& rows) {
  fixed_.assign(4 * static_cast<std::size_t>(numbering_.owned), 0);
  const PetscInt first = 4 * static_cast<PetscInt>(numbering_.range.first);
  for (PetscInt r : rows) fixed_[static_cast<std::size_t>(r - first)] = 1;
  PetscInt local = 0, global = 0;
  petsc::check(MatGetLocalSize(matrix_, &local, nullptr), "MatGetLocalSize");
  petsc::check(MatGetSize(matrix_, &global, nullptr), "MatGetSize");
  petsc::check(MatCreateShell(PetscObjectComm(reinterpret_cast<PetscObject>(matrix_.get())), local,
                              local, global, global, this, newton_operator_.out()),
               "MatCreateShell");
  petsc::check(MatShellSetOperation(newton_operator_, MATOP_MULT,
                                    reinterpret_cast<void (*)(void)>(&OseenSystem::newton_product)),
               "MatShellSetOperation");
  petsc::check(VecDuplicate(piece_, operand_.out()), "VecDuplicate");
  petsc::check(VecDuplicate(piece_, product_.out()), "VecDuplicate");
}

Mat OseenSystem::newton_operator(const std::vector<Eigen::Vector3d>& advection, double nu) {
  // Allocated at first use: most runs never take such a step.
  if (!derivative_)
    derivative_.emplace(mesh_, OwnedCells{all_cells_, owned_tets_, owned_pyramids_, owned_hexes_});
  const petsc::LoggedEvent logged("NSWholeDerivative");
  derivative_->assemble(advection, nu);
  return newton_operator_;
}

void OseenSystem::recover_gradient(const std::vector<Eigen::Vector3d>& a) {
  // Every cell of the piece: the gradient is needed at the nodes of owned cells, and the
  // piece holds all the cells around those.
  ns::recover_gradient(mesh_, a, gradient_, lumped_mass_);
}

void OseenSystem::velocity_mass(Vec v) const {
  petsc::check(VecSet(v, 0.0), "VecSet");
  PetscScalar* d = nullptr;
  petsc::check(VecGetArray(v, &d), "VecGetArray");
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i)
    for (std::size_t c = 0; c < 3; ++c) d[4 * i + c] = lumped_mass_[i];
  petsc::check(VecRestoreArray(v, &d), "VecRestoreArray");
}

void OseenSystem::add_pseudo_time(const std::vector<Eigen::Vector3d>& advection, double nu,
                                  double cfl) {
  PetscScalar* d = nullptr;
  petsc::check(VecSet(scratch_, 0.0), "VecSet");
  petsc::check(VecGetArray(scratch_, &d), "VecGetArray");
  for (std::size_t i = 0; i < static_cast<std::size_t>(numbering_.owned); ++i) {
    const double m = lumped_mass_[i];
    if (!(m > 0.0)) continue;
    const double h = std::cbrt(m);
    const double rate = (advection[i].norm() + nu / h) / (cfl * h);
    for (int c = 0; c < 3; ++c) d[4 * i + static_cast<std::size_t>(c)] = m * rate;
  }
  petsc::check(VecRestoreArray(scratch_, &d), "VecRestoreArray");
  petsc::check(MatDiagonalSet(matrix_, scratch_, ADD_VALUES), "MatDiagonalSet");
}

void OseenSystem::assemble(const std::vector<Eigen::Vector3d>& advection,
                           const std::vector<double>& pressure, double nu, const BodyForce& force,
                           Linearization linearization) {
  const petsc::LoggedEvent logged("NSAssembly");
  recover_gradient(advection);
  petsc::check(MatZeroEntries(matrix_), "MatZeroEntries");
  petsc::check(VecSet(rhs_, 0.0), "VecSet");
  petsc::check(VecSet(residual_, 0.0), "VecSet");
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
  if (!backflow_.patches.empty()) assemble_backflow(advection, linearization);
  petsc::check(MatAssemblyBegin(matrix_, MAT_FINAL_ASSEMBLY), "MatAssemblyBegin");
  petsc::check(MatAssemblyEnd(matrix_, MAT_FINAL_ASSEMBLY), "MatAssemblyEnd");
  for (Vec v : {rhs_.get(), residual_.get()}) {
    petsc::check(VecAssemblyBegin(v), "VecAssemblyBegin");
    petsc::check(VecAssemblyEnd(v), "VecAssemblyEnd");
  }
}

void OseenSystem::assemble_backflow(const std::vector<Eigen::Vector3d>& advection,
                                    Linearization linearization) {
  const bool newton = linearization == Linearization::newton;
  auto face = [&](std::span<const NodeId> v, double beta) {
    const int m = static_cast<int>(v.size());
    const auto node = [&](int i) {
      return static_cast<std::size_t>(v[static_cast<std::size_t>(i)]);
    };
    Eigen::Matrix4d M;
    // Newton's share, d/du of the term with a = u: −β ∫ (u·n)₋' (δu·n) (u·w); rows and
    // columns (4i + c) like PETSc's block.
    Eigen::Matrix<double, 16, 16> D;
    backflow_face(mesh_, v, advection, beta, backflow_.smoothing, M, newton ? &D : nullptr);
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
    petsc::check(
        MatSetValuesBlocked(matrix_, m, ids.data(), m, ids.data(), block.data(), ADD_VALUES),
        "MatSetValuesBlocked");
    if (linearization != Linearization::picard)
      petsc::check(VecSetValuesBlocked(residual_, m, ids.data(), r.data(), ADD_VALUES),
                   "VecSetValuesBlocked");
  };
  for_each_boundary_face(mesh_, [&](std::span<const NodeId> v, int patch) {
    const double beta = backflow_.beta(patch);
    if (beta != 0.0) face(v, beta);
  });
}

template <class E, class Cells, class Force>
void OseenSystem::assemble_cells(const Cells& all, const std::vector<std::size_t>& owned,
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
    petsc::check(VecSetValuesBlocked(rhs_, N, blocks.data(), sys.F.data(), ADD_VALUES),
                 "VecSetValuesBlocked");
    if (linearization != Linearization::picard)
      petsc::check(VecSetValuesBlocked(residual_, N, blocks.data(), sys.R.data(), ADD_VALUES),
                   "VecSetValuesBlocked");
  }
}

PetscErrorCode OseenSystem::newton_product(Mat shell, Vec x, Vec y) {
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
  PetscCall(
      VecScatterBegin(self->gather_, self->product_, self->scratch_, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(
      VecScatterEnd(self->gather_, self->product_, self->scratch_, ADD_VALUES, SCATTER_REVERSE));
  PetscCall(VecGetArray(self->scratch_, &out));
  for (std::size_t r = 0; r < self->fixed_.size(); ++r)
    if (self->fixed_[r]) out[r] = 0.0;
  PetscCall(VecRestoreArray(self->scratch_, &out));
  PetscCall(VecAXPY(y, -1.0, self->scratch_));
  return 0;
}

}  // namespace naris::ns
