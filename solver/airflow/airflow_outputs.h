#pragma once
// What `naris solve` writes once the target is reached: the flow's numbers in SI (flow,
// pressure drop, resistance, forces, wall shear) and its files (solution.vtu or .pvtu,
// boundary.vtp, solution.h5 + .xdmf, residuals.csv, summary.json).
#include "mesh/hybrid_mesh.h"
#include "mesh/patches/patches.h"
#include "solver/airflow/airflow_job.h"
#include "solver/airflow/piece_solves.h"
#include "solver/airflow/solution_file.h"
#include "solver/parallel/partition.h"

namespace naris::airflow {

// This rank's piece of the (nondimensional) mesh, and what the first rank keeps of the whole
// for the files it alone writes.
struct Partition {
  parallel::MeshPiece piece;
  HybridMesh surface;  // the whole boundary, on the first of several ranks
  MeshCounts counts;   // of the whole mesh
  std::size_t boundary_faces = 0;
};
Partition partition(HybridMesh mesh, int rank, int ranks);

// The SI results into r and every file but summary.json. Collective.
// `openings`: the inlet's (mesh/patches/patches.h), of the whole mesh in mm.
void write_airflow_outputs(const AirflowJob& job, Partition& part, const PieceSolves& solves,
                           const ns::FlowField& field, const PatchOpenings& openings,
                           AirflowResult& r);
// summary.json, on the first rank, last.
void write_summary_json(const AirflowJob& job, AirflowResult& r);

}  // namespace naris::airflow
