#pragma once
// The files of `naris trace` (docs/formats.md): paths.vtp, deposits.vtp, particles.csv,
// crossings.csv, fates.csv and summary.json.
#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/airflow/solution_file.h"
#include "solver/particles/trace_job.h"

namespace naris::particles {

struct TraceData {
  const TraceJob& job;
  const TraceResult& result;
  const ReleaseSet& release;
  const std::vector<ParticleKind>& kinds;
  const std::vector<Plane>& planes;
  const std::vector<std::string>& plane_labels;
  const std::vector<ParticleResult>& particles;  // id = species × release points + point
  const HybridMesh& mesh;
  const airflow::SolutionState& solution;
};

void write_trace_outputs(const TraceData& data);

}  // namespace naris::particles
