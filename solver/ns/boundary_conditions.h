#pragma once
// Boundary conditions of the airflow problem from the mesh's named patches: velocity into the
// inlet patch along its inward normal — uniform (the dissertation's standard case), fully
// developed (the Poisson solution −Δw = 1 on the inlet face, w = 0 on its rim, which is the
// laminar profile of a duct of that shape) or given by a function — no slip on every other
// patch except the outlet, where the natural (traction-free) condition holds.
#include <functional>
#include <string>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_field.h"

namespace naris::ns {

enum class InletProfile { uniform, developed, expression };

// A profile shape: the value at position x and distance r from the inlet's centroid (both in
// the mesh's length unit).
using ProfileShape = std::function<double(const Eigen::Vector3d& x, double r)>;

struct InletSummary {
  double area = 0.0;                                 // of the inlet patch
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, pointing into the domain
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double flux = 0.0;  // ∫ u·n_in dA of the imposed velocity
};

// Dirichlet data for mean inlet speed `mean_speed`; `shape` (for InletProfile::expression) is
// scaled to that mean. Throws naris::Error when the mesh has no `inlet` or no `outlet` patch,
// the inlet is not a planar face, or the shape is not finite, negative somewhere or zero
// everywhere. Nodes on the rim of the inlet belong to the wall (no slip wins).
DirichletConditions airflow_conditions(const HybridMesh& mesh, InletProfile profile,
                                       double mean_speed, InletSummary* summary = nullptr,
                                       const ProfileShape& shape = {});

// The same with a profile given as a function of the position (speed along the inward normal).
DirichletConditions airflow_conditions(const HybridMesh& mesh,
                                       const std::function<double(const Eigen::Vector3d&)>& speed,
                                       InletSummary* summary = nullptr);

}  // namespace naris::ns
