#pragma once
// The flow solution on disk (HDF5): the nondimensional nodal velocity and pressure, the Reynolds
// number they belong to, the scales, and a fingerprint of the mesh they were computed on. The
// same layout serves as the continuation checkpoint (rewritten after every converged step) and
// as `solution.h5`, which also holds the SI fields and has an XDMF sidecar that takes the
// geometry from the mesh file, so ParaView opens it.
//
//   /  attributes format = "naris-solution", version, reynolds, target_reynolds, u_in (m/s),
//      d_in_mm, density, viscosity, mesh_fingerprint (hex), nodes, mesh_file (solution.h5 only:
//      the mesh.h5, relative to this file's folder)
//   /velocity_nondimensional [nodes, 3], /pressure_nondimensional [nodes]
//   /velocity [nodes, 3] (m/s), /pressure [nodes] (Pa)             (solution.h5 only)
//
// A checkpoint also holds where the continuation stood, so that a restart takes the path the
// uninterrupted run would have taken (checkpoint.h5 only; a file without them restarts with a
// quarter of the Re reached as the increment, Newton first):
//
//   /  attributes next_step (the increment of Re to try next), pseudo_time (1: the step
//      converged with pseudo-time, which the next one tries first), earlier_reynolds (the
//      converged step before, 0: none), arclength_step (present when the run was following
//      the branch by arclength: the next arclength increment; the earlier step is then the
//      branch's point before, at any Re but this one)
//   /earlier_velocity_nondimensional, /earlier_pressure_nondimensional  (earlier_reynolds > 0)
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/continuation/reynolds_continuation.h"
#include "solver/ns/flow_field.h"

namespace naris::airflow {

struct SolutionState {
  ns::FlowField field;  // nondimensional
  double reynolds = 0.0, target_reynolds = 0.0;
  double u_in = 0.0, d_in_mm = 0.0, density = 0.0, viscosity = 0.0;
  std::uint64_t mesh_fingerprint = 0;
  std::filesystem::path mesh_file;               // read: absolute, empty when the file names none
  continuation::ContinuationState continuation;  // written when next_step > 0
};

// The sizes the XDMF sidecar names: the rank that writes it need not hold the mesh.
struct MeshCounts {
  std::size_t nodes = 0, tets = 0, pyramids = 0, hexes = 0;
};
MeshCounts mesh_counts(const HybridMesh& mesh);

// FNV-1a over the node coordinates and the cells: equal meshes, equal fingerprints.
std::uint64_t mesh_fingerprint(const HybridMesh& mesh);

// Writes atomically. With `mesh` (the sizes of mesh_file, the mesh.h5 the solution belongs
// to), also writes the SI fields and the XDMF sidecar beside `path`.
void write_solution_h5(const SolutionState& state, const std::filesystem::path& path,
                       const MeshCounts* mesh = nullptr,
                       const std::filesystem::path& mesh_file = {});

// Throws naris::Error for a missing, unreadable or foreign file.
SolutionState read_solution_h5(const std::filesystem::path& path);

// A solution with the mesh it was solved on: `mesh_file` (default: the one the solution names),
// checked by fingerprint; `velocity` in m/s. Throws naris::Error for a solution of another mesh.
struct SolvedMesh {
  SolutionState state;
  std::filesystem::path mesh_file;
  HybridMesh mesh;
  std::vector<Eigen::Vector3d> velocity;
};
SolvedMesh read_solved_mesh(const std::filesystem::path& solution,
                            const std::filesystem::path& mesh_file = {});
// The same for a solution already read from `solution` (named in the errors).
SolvedMesh attach_mesh(SolutionState state, const std::filesystem::path& solution,
                       const std::filesystem::path& mesh_file = {});

}  // namespace naris::airflow
