#pragma once
// The settings tables of the stages that both a command and a case file run: interpolate,
// segment, mesh, solve, trace and planes. Each holds the library's job with its defaults, the table
// bound to it, and resolves the two into the job to run.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "app/settings.h"
#include "mesh/image/image_jobs.h"
#include "mesh/pipeline/mesh_job.h"
#include "postproc/planes/planes_job.h"
#include "solver/airflow/airflow_job.h"
#include "solver/particles/trace_job.h"

namespace naris::app {

// Relative paths in a case file are relative to the case file's folder (`base`); on the command
// line to the working directory (`base` empty).
std::filesystem::path resolve_path(const std::filesystem::path& base,
                                   const std::filesystem::path& p);

// A stage's job with the library's defaults and the table bound to its fields (not copyable,
// as the table is not: it points into the job).
template <class Job>
struct StageSettings {
  Job job;
  Settings table;
};

struct InterpolateSettings : StageSettings<InterpolateJob> {
  std::string method = "hsr";
  InterpolateSettings();
  InterpolateJob resolve() const;
};

struct SegmentSettings : StageSettings<SegmentJob> {
  std::string inside = "below";
  bool all_components = !job.keep_largest;
  std::string side = "right", nasopharynx = "cut";
  SegmentSettings();
  SegmentJob resolve() const;
};

struct MeshSettings : StageSettings<MeshJob> {
  std::string inside = "below";
  bool all_components = !job.keep_largest;
  MeshSettings();
  MeshJob resolve() const;
};

struct SolveSettings : StageSettings<airflow::AirflowJob> {
  std::string inlet_profile = "uniform", scheme = "coupled", drive = "inlet", petsc;
  std::optional<std::string> restart, restart_mesh;
  bool rebuild_preconditioner = !job.nonlinear.reuse_preconditioner;
  bool verbose = job.nonlinear.log_iterations;
  SolveSettings();
  airflow::AirflowJob resolve(const std::filesystem::path& base = {}) const;
};

struct TraceSettings : StageSettings<particles::TraceJob> {
  std::string diameter, density = "1000", planes;
  std::optional<std::string> mesh, points;
  bool figures = true;
  TraceSettings();
  particles::TraceJob resolve(const std::filesystem::path& base = {}) const;
};

struct PlanesSettings : StageSettings<planes::PlanesJob> {
  std::string at = "33.5,44,54.5,65,75.5,85";
  std::optional<std::string> mesh, crossings;
  PlanesSettings();
  planes::PlanesJob resolve(const std::filesystem::path& base = {}) const;
};

}  // namespace naris::app
