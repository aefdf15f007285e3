#include "solver/ns/reaction_force.h"

#include <petscvec.h>

#include <cstdlib>

#include "solver/ns/backflow.h"
#include "solver/ns/oseen_element.h"
#include "solver/ns/recovered_gradient.h"
#include "solver/parallel/petsc.h"

namespace naris::ns {
namespace {

using petsc::check;

// Per node, summed over the ranks: the reaction R_i (3), then per patch ∫ N_i (1) and a known
// part of the traction σn against N_i (3): on prescribed patches the whole, estimated from the
// recovered gradient; on walls the pressure's −p n, exact for the discrete pressure.
constexpr int kReaction = 3, kPerPatch = 4;

// Adds the owned cells' momentum residuals at nodes with Dirichlet velocity into `row`.
template <class E, class Cells>
void add_cell_residuals(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                        const Cells& cells, const FlowField& field,
                        const std::vector<Eigen::Matrix<double, 1, 9>>& gradient,
                        const std::vector<char>& fixed, const FlowProblem& problem,
                        std::vector<double>& rows, int stride) {
  constexpr int N = E::nodes;
  const double nu = 1.0 / problem.reynolds;
  const auto force = [&](const Eigen::Vector3d& x) -> Eigen::Vector3d {
    return problem.force ? problem.force(x) : Eigen::Vector3d::Zero();
  };
  Eigen::Matrix<double, N, 3> X, a;
  Eigen::Matrix<double, N, 1> p;
  Eigen::Matrix<double, N, 9> grad;
  ElementSystem<N> sys;
  for (const auto& cell : cells) {
    bool any = false;
    for (NodeId v : cell) any = any || fixed[static_cast<std::size_t>(v)];
    if (!any || !numbering.owns_cell(cell)) continue;
    for (int i = 0; i < N; ++i) {
      const auto n = static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]);
      X.row(i) = piece.nodes[n].transpose();
      a.row(i) = field.velocity[n].transpose();
      grad.row(i) = gradient[n];
      p[i] = field.pressure[n];
    }
    oseen_element<E>(X, a, &grad, nu, force, sys, p, Linearization::picard_residual);
    for (int i = 0; i < N; ++i) {
      const auto n = static_cast<std::size_t>(cell[static_cast<std::size_t>(i)]);
      if (!fixed[n]) continue;
      for (int c = 0; c < 3; ++c)
        rows[n * static_cast<std::size_t>(stride) + static_cast<std::size_t>(c)] +=
            sys.R[4 * i + c];
    }
  }
}

}  // namespace

std::vector<PatchKind> airflow_patch_kinds(const HybridMesh& mesh, DrivenPatch driven) {
  std::vector<PatchKind> kinds(mesh.patch_names.size(), PatchKind::wall);
  const bool from_inlet = driven == DrivenPatch::inlet;
  for (std::size_t q = 0; q < kinds.size(); ++q) {
    if (mesh.patch_names[q] == "inlet")
      kinds[q] = from_inlet ? PatchKind::prescribed : PatchKind::natural;
    if (mesh.patch_names[q] == "outlet")
      kinds[q] = from_inlet ? PatchKind::natural : PatchKind::prescribed;
  }
  return kinds;
}

Reactions reaction_forces(const HybridMesh& piece, const parallel::NodeNumbering& numbering,
                          const FlowField& field, const FlowProblem& problem,
                          const std::vector<PatchKind>& kinds, MPI_Comm comm) {
  const int patches = static_cast<int>(kinds.size());
  const int stride = kReaction + kPerPatch * patches;
  const std::size_t nodes = piece.nodes.size();
  std::vector<char> fixed(nodes, 0);
  for (NodeId n : problem.conditions.nodes) fixed[static_cast<std::size_t>(n)] = 1;
  std::vector<Eigen::Matrix<double, 1, 9>> gradient;
  std::vector<double> mass;
  recover_gradient(piece, field.velocity, gradient, mass);

  std::vector<double> rows(nodes * static_cast<std::size_t>(stride), 0.0);
  add_cell_residuals<fem::Tet4>(piece, numbering, piece.tets, field, gradient, fixed, problem, rows,
                                stride);
  add_cell_residuals<fem::Pyr5>(piece, numbering, piece.pyramids, field, gradient, fixed, problem,
                                rows, stride);
  add_cell_residuals<fem::Hex8>(piece, numbering, piece.hexes, field, gradient, fixed, problem,
                                rows, stride);
  // The piece's boundary faces are the ones this rank owns: ∫ N_i over each; on prescribed
  // patches ∫ σn N_i with σn = −p n + ν (∇u) n, the traction of the weak form's Laplacian
  // viscous term; on walls ∫ −p n N_i (the consistent mass of a flat triangle or
  // parallelogram: exact for the nodal pressure).
  const double nu = 1.0 / problem.reynolds;
  for_each_boundary_face(piece, [&](std::span<const NodeId> v, int patch) {
    const Eigen::Vector3d an = polygon_vector_area(piece, v);
    const double area = an.norm();
    if (area <= 0.0) return;
    const Eigen::Vector3d normal = an / area;
    const int m = static_cast<int>(v.size());
    const PatchKind kind = kinds[static_cast<std::size_t>(patch)];
    // The known traction at the corners: none on natural patches.
    Eigen::Vector3d known[4];
    for (int j = 0; j < m && kind != PatchKind::natural; ++j) {
      const auto n = static_cast<std::size_t>(v[static_cast<std::size_t>(j)]);
      known[j] = -field.pressure[n] * normal;
      if (kind == PatchKind::prescribed)
        known[j] +=
            nu *
            Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(gradient[n].data()) *
            normal;
    }
    const std::size_t base = kReaction + static_cast<std::size_t>(kPerPatch * patch);
    for (int i = 0; i < m; ++i) {
      const auto n = static_cast<std::size_t>(v[static_cast<std::size_t>(i)]);
      if (!fixed[n]) continue;  // the rest carry no reaction
      double* row = rows.data() + n * static_cast<std::size_t>(stride) + base;
      row[0] += area / m;
      if (kind == PatchKind::natural) continue;
      Eigen::Vector3d s = Eigen::Vector3d::Zero();
      for (int j = 0; j < m; ++j) {
        const int apart = std::abs(i - j);  // quadrilateral: 2 is the opposite corner
        s += (m == 3 ? area / 12.0 * (apart == 0 ? 2.0 : 1.0)
                     : area / 36.0 *
                           (apart == 0   ? 4.0
                            : apart == 2 ? 1.0
                                         : 2.0)) *
             known[j];
      }
      for (int c = 0; c < 3; ++c) row[1 + c] += s[c];
    }
  });

  // The backflow term B_i (backflow.h) is a natural patch's traction on the fluid, −B_i against
  // N_i: the patch bears Σ B_i, and a wall node on its rim R_i + B_i.
  std::vector<double> force(3 * static_cast<std::size_t>(patches), 0.0);
  if (!problem.backflow.patches.empty()) {
    Eigen::Matrix4d M;
    for_each_boundary_face(piece, [&](std::span<const NodeId> v, int patch) {
      const double beta = problem.backflow.beta(patch);
      if (beta == 0.0) return;
      backflow_face(piece, v, field.velocity, beta, problem.backflow.smoothing, M, nullptr);
      for (std::size_t i = 0; i < v.size(); ++i) {
        Eigen::Vector3d b = Eigen::Vector3d::Zero();
        for (std::size_t j = 0; j < v.size(); ++j)
          b += M(static_cast<int>(i), static_cast<int>(j)) *
               field.velocity[static_cast<std::size_t>(v[j])];
        for (int c = 0; c < 3; ++c) force[3 * static_cast<std::size_t>(patch) + c] += b[c];
        const auto n = static_cast<std::size_t>(v[i]);
        if (fixed[n])
          for (int c = 0; c < 3; ++c) rows[n * static_cast<std::size_t>(stride) + c] += b[c];
      }
    });
  }

  // The rows summed on their owners.
  petsc::Vector sums;
  check(VecCreate(comm, sums.out()), "VecCreate");
  check(VecSetSizes(sums, stride * static_cast<PetscInt>(numbering.owned), PETSC_DETERMINE),
        "VecSetSizes");
  check(VecSetBlockSize(sums, stride), "VecSetBlockSize");
  check(VecSetType(sums, VECMPI), "VecSetType");
  check(VecSet(sums, 0.0), "VecSet");
  for (std::size_t n = 0; n < nodes; ++n) {
    if (!fixed[n]) continue;
    const PetscInt block = numbering.to_global(static_cast<NodeId>(n));
    check(VecSetValuesBlocked(sums, 1, &block, rows.data() + n * static_cast<std::size_t>(stride),
                              ADD_VALUES),
          "VecSetValuesBlocked");
  }
  check(VecAssemblyBegin(sums), "VecAssemblyBegin");
  check(VecAssemblyEnd(sums), "VecAssemblyEnd");

  // The walls' viscous traction on the owned nodes, then on every node of the piece.
  petsc::Vector traction;
  check(VecCreate(comm, traction.out()), "VecCreate");
  check(VecSetSizes(traction, 3 * static_cast<PetscInt>(numbering.owned), PETSC_DETERMINE),
        "VecSetSizes");
  check(VecSetBlockSize(traction, 3), "VecSetBlockSize");
  check(VecSetType(traction, VECMPI), "VecSetType");
  check(VecSet(traction, 0.0), "VecSet");
  PetscScalar* owned_traction = nullptr;
  check(VecGetArray(traction, &owned_traction), "VecGetArray");
  const PetscScalar* all = nullptr;
  check(VecGetArrayRead(sums, &all), "VecGetArrayRead");
  for (NodeId k = 0; k < numbering.owned; ++k) {
    const double* row = all + static_cast<std::size_t>(k) * static_cast<std::size_t>(stride);
    const auto mass_of = [&](int q) { return row[kReaction + kPerPatch * q]; };
    Eigen::Vector3d rest(row[0], row[1], row[2]);
    double wall_mass = 0.0, prescribed_mass = 0.0;
    for (int q = 0; q < patches; ++q) {
      if (mass_of(q) <= 0.0) continue;
      if (kinds[static_cast<std::size_t>(q)] == PatchKind::wall) wall_mass += mass_of(q);
      if (kinds[static_cast<std::size_t>(q)] == PatchKind::prescribed)
        prescribed_mass += mass_of(q);
    }
    if (wall_mass + prescribed_mass <= 0.0) continue;  // inside the domain: no boundary's force
    // Prescribed patches take their traction's integral where walls share the node; alone
    // they share the reaction by area (natural patches carry none).
    for (int q = 0; q < patches; ++q) {
      if (mass_of(q) <= 0.0 || kinds[static_cast<std::size_t>(q)] != PatchKind::prescribed)
        continue;
      Eigen::Vector3d part;
      if (wall_mass > 0.0) {
        const double* s = row + kReaction + kPerPatch * q + 1;
        part = Eigen::Vector3d(s[0], s[1], s[2]);
      } else {
        part = Eigen::Vector3d(row[0], row[1], row[2]) * (mass_of(q) / prescribed_mass);
      }
      rest -= part;
      for (int c = 0; c < 3; ++c) force[3 * static_cast<std::size_t>(q) + c] -= part[c];
    }
    if (wall_mass <= 0.0) continue;
    // The walls share the rest by area; less their pressure part it is the viscous traction.
    Eigen::Vector3d viscous = rest;
    for (int q = 0; q < patches; ++q) {
      if (mass_of(q) <= 0.0 || kinds[static_cast<std::size_t>(q)] != PatchKind::wall) continue;
      viscous -= Eigen::Map<const Eigen::Vector3d>(row + kReaction + kPerPatch * q + 1);
      for (int c = 0; c < 3; ++c)
        force[3 * static_cast<std::size_t>(q) + c] -= rest[c] * mass_of(q) / wall_mass;
    }
    for (int c = 0; c < 3; ++c)
      owned_traction[3 * static_cast<std::size_t>(k) + static_cast<std::size_t>(c)] =
          -viscous[c] / wall_mass;
  }
  check(VecRestoreArrayRead(sums, &all), "VecRestoreArrayRead");
  check(VecRestoreArray(traction, &owned_traction), "VecRestoreArray");
  MPI_Allreduce(MPI_IN_PLACE, force.data(), static_cast<int>(force.size()), MPI_DOUBLE, MPI_SUM,
                comm);
  Reactions out;
  out.patches.resize(static_cast<std::size_t>(patches));
  for (int q = 0; q < patches; ++q)
    out.patches[static_cast<std::size_t>(q)] = {force[3 * q], force[3 * q + 1], force[3 * q + 2]};

  std::vector<PetscInt> global(nodes);
  for (std::size_t n = 0; n < nodes; ++n) global[n] = numbering.to_global(static_cast<NodeId>(n));
  petsc::IndexSet wanted;
  check(ISCreateBlock(PETSC_COMM_SELF, 3, static_cast<PetscInt>(nodes), global.data(),
                      PETSC_COPY_VALUES, wanted.out()),
        "ISCreateBlock");
  petsc::Vector local;
  check(VecCreateSeq(PETSC_COMM_SELF, 3 * static_cast<PetscInt>(nodes), local.out()),
        "VecCreateSeq");
  petsc::Scatter scatter;
  check(VecScatterCreate(traction, wanted, local, nullptr, scatter.out()), "VecScatterCreate");
  check(VecScatterBegin(scatter, traction, local, INSERT_VALUES, SCATTER_FORWARD),
        "VecScatterBegin");
  check(VecScatterEnd(scatter, traction, local, INSERT_VALUES, SCATTER_FORWARD), "VecScatterEnd");
  const PetscScalar* t = nullptr;
  check(VecGetArrayRead(local, &t), "VecGetArrayRead");
  out.viscous_traction.resize(nodes);
  for (std::size_t n = 0; n < nodes; ++n)
    out.viscous_traction[n] = {t[3 * n], t[3 * n + 1], t[3 * n + 2]};
  check(VecRestoreArrayRead(local, &t), "VecRestoreArrayRead");
  return out;
}

std::vector<Eigen::Vector3d> consistent_wall_shear(const HybridMesh& piece,
                                                   const Reactions& reactions,
                                                   const std::vector<PatchKind>& kinds) {
  std::vector<Eigen::Vector3d> shear;
  shear.reserve(piece.boundary_tris.size() + piece.boundary_quads.size());
  for_each_boundary_face(piece, [&](std::span<const NodeId> v, int patch) {
    const Eigen::Vector3d an = polygon_vector_area(piece, v);
    if (kinds[static_cast<std::size_t>(patch)] != PatchKind::wall || !(an.norm() > 0.0)) {
      shear.push_back(Eigen::Vector3d::Zero());
      return;
    }
    const Eigen::Vector3d n = an.normalized();
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    for (NodeId k : v) t += reactions.viscous_traction[static_cast<std::size_t>(k)];
    t /= static_cast<double>(v.size());
    shear.push_back(t - t.dot(n) * n);
  });
  return shear;
}

}  // namespace naris::ns
