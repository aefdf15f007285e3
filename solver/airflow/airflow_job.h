#pragma once
// `naris solve` as a library call: the steady airflow in a mesh made by `naris mesh` at a
// target Reynolds number on the naris hydraulic diameter, reached by continuation in Re, in
// nondimensional variables (x* = x/d_in, u* = u/U_in, p* = p/(ρU_in²); eq. 4.3–4.7), reported
// and written in SI.
#include <Eigen/Dense>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "solver/continuation/reynolds_continuation.h"
#include "solver/ns/boundary_conditions.h"
#include "solver/stability/linear_stability.h"

namespace naris::airflow {

// The defaults of `naris solve`: pseudo-time on, since on real anatomy Newton alone stalls
// where the jet changes branch (docs/method/continuation.md).
inline nonlinear::NonlinearOptions airflow_nonlinear_defaults() {
  nonlinear::NonlinearOptions o;
  o.pseudo_cfl = 5.0;
  return o;
}

struct AirflowJob {
  std::filesystem::path mesh;                 // mesh.h5 with inlet and outlet patches
  std::filesystem::path output = "solution";  // folder
  double reynolds = 610.0;                    // target, on d_in = 4A/P of the inlet
  std::optional<double> inlet_speed;          // m/s; when given, Re follows from it
  double viscosity = 1.5e-5;                  // kinematic, m²/s (air)
  double density = 1.2;                       // kg/m³ (air)
  ns::InletProfile profile = ns::InletProfile::uniform;
  std::string inlet_expression;  // with InletProfile::expression (inlet_expression.h)
  // Where the flow is imposed: blown into the inlet (the outlet traction-free), or drawn out of
  // the outlet with the inlet open to still air at ambient total pressure, so that its openings
  // (both nares) share the flow as the flow decides. Either way the flux is U_in × inlet area.
  ns::DrivenPatch drive = ns::DrivenPatch::inlet;
  double backflow_smoothing = 0.0;  // of the natural patch's switch, in mean inlet speeds
  int stability_modes = 0;  // eigenvalues of the steady flow's linearization (stability/), 0: none
  double start_reynolds = 50.0;  // the first continuation step
  int max_steps = 40;            // continuation steps, failed ones included
  double step_tolerance = 1e-5;  // of the steps before the target (reynolds_continuation.h)
  int arclength_steps = 30;      // points of the branch followed past a stall (0: fail there)
  nonlinear::NonlinearOptions nonlinear = airflow_nonlinear_defaults();  // per step
  // Resume from this checkpoint (a solution file of the same mesh) instead of starting low.
  std::optional<std::filesystem::path> restart;
  // The mesh `restart` was computed on, when `mesh` is that mesh subdivided (naris mesh
  // --subdivide): the field is prolonged onto this mesh (the parent's interpolant at every new
  // node), and a checkpoint at the target itself is the start of the target's step — a
  // mesh-convergence study warm-started from the coarser mesh.
  std::optional<std::filesystem::path> restart_mesh;
};

struct AirflowResult {
  double d_in_mm = 0.0, inlet_area_mm2 = 0.0, inlet_perimeter_mm = 0.0;
  double u_in = 0.0, reynolds = 0.0;
  double flow_ml_s = 0.0, pressure_drop_pa = 0.0, resistance = 0.0, max_speed = 0.0;
  double inlet_flow_ml_s = 0.0, outlet_flow_ml_s = 0.0;  // measured: the mass balance
  // Driven at the outlet: the drop from the ambient air (total pressure 0) to the outlet's
  // area-averaged pressure, what rhinomanometry measures; 0 otherwise.
  double ambient_drop_pa = 0.0;
  // The inlet patch's connected pieces (the nares), largest first, and the flow through each.
  struct Opening {
    double area_mm2 = 0.0;
    Eigen::Vector3d centroid_mm = Eigen::Vector3d::Zero();
    double flow_ml_s = 0.0;
  };
  std::vector<Opening> openings;
  struct Patch {
    std::string name;
    double area_mm2 = 0.0;
    Eigen::Vector3d force = Eigen::Vector3d::Zero();  // consistent (ns/reaction_force.h)
    // The surface integral of the traction from the cells' gradients, to compare.
    Eigen::Vector3d pressure_force = Eigen::Vector3d::Zero(),
                    viscous_force = Eigen::Vector3d::Zero();
    double mean_shear = 0.0, max_shear = 0.0;  // Pa
  };
  std::vector<Patch> patches;  // forces (N) and wall shear stress per patch
  // |Σ patch forces + momentum carried out| over the largest wall force: how well the
  // consistent forces close the momentum balance.
  double momentum_balance = 0.0;
  // The linearization's eigenvalues nearest zero at the answer, in U_in/d_in (linear_stability.h).
  std::vector<stability::Mode> modes;
  std::vector<continuation::ContinuationStep> steps;
  std::size_t cells = 0, nodes = 0;
  double seconds = 0.0, restarted_from = 0.0;  // the checkpoint's Re, 0 without --restart
  int ranks = 1;                               // MPI ranks that shared the solve
  std::size_t peak_memory = 0;                 // bytes, the largest of any rank
  std::size_t total_peak_memory = 0;           // bytes, summed over the ranks
  std::vector<std::string> written;
};

// Throws naris::Error for a bad mesh or setting, or when the continuation cannot reach the
// target (with the last Re reached; the files of the last converged step are still written).
AirflowResult run_airflow_job(const AirflowJob& job);
std::string format_airflow_summary(const AirflowJob& job, const AirflowResult& r);

}  // namespace naris::airflow
