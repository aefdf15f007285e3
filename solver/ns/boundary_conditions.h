#pragma once
// Boundary conditions of the airflow problem from the mesh's named patches: the velocity on the
// driven patch along its normal — uniform (the dissertation's standard case), fully developed
// (the Poisson solution −Δw = 1 on the face, w = 0 on its rim, which is the laminar profile of a
// duct of that shape) or given by a function — no slip on every patch but the inlet and the
// outlet, and the natural condition on the one of those that is not driven. Driven at the inlet,
// air is blown in and the outlet is traction-free; driven at the outlet, air is drawn out and
// the inlet (both nares, say) is open to still air, so its openings share the flow as the flow
// decides.
#include <functional>
#include <string>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_field.h"

namespace naris::ns {

enum class InletProfile { uniform, developed, expression };

// The patch whose velocity is imposed; the other of `inlet` and `outlet` is natural.
enum class DrivenPatch { inlet, outlet };

// A profile shape: the value at position x and distance r from the inlet's centroid (both in
// the mesh's length unit).
using ProfileShape = std::function<double(const Eigen::Vector3d& x, double r)>;

// The driven patch (the inlet unless said otherwise).
struct InletSummary {
  double area = 0.0;                                 // of the driven patch
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // unit, pointing into the domain
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  double flux = 0.0;  // ∫ u·n dA of the imposed velocity, n along the flow (in at the inlet,
                      // out at the outlet)
};

// Dirichlet data for mean speed `mean_speed` over the driven patch, into the domain at the
// inlet, out of it at the outlet; `shape` (for InletProfile::expression) is scaled to that mean.
// Throws naris::Error when the mesh has no `inlet` or no `outlet` patch, or the shape is not
// finite, negative somewhere or zero everywhere. Nodes on the rim of the driven patch belong to
// the wall (no slip wins).
DirichletConditions airflow_conditions(const HybridMesh& mesh, InletProfile profile,
                                       double mean_speed, InletSummary* summary = nullptr,
                                       const ProfileShape& shape = {},
                                       DrivenPatch driven = DrivenPatch::inlet);

// The same with a profile given as a function of the position (speed along the inward normal).
DirichletConditions airflow_conditions(const HybridMesh& mesh,
                                       const std::function<double(const Eigen::Vector3d&)>& speed,
                                       InletSummary* summary = nullptr);

}  // namespace naris::ns
