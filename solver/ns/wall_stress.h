#pragma once
// What the fluid exerts on the boundary, from a nondimensional flow field: per boundary face the
// traction −σn = p n − (1/Re)(∇u + ∇uᵀ) n (n outward from the fluid) from the gradient of the
// cell that owns the face (taken at the face's centroid), its tangential part (the wall shear
// stress, along the near-wall flow), and per patch the pressure and viscous forces. All in
// nondimensional units (scale stresses by ρU², forces by ρU²d²).
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "solver/ns/flow_field.h"

namespace naris::ns {

struct PatchForce {
  std::string name;
  double area = 0.0;
  Eigen::Vector3d pressure = Eigen::Vector3d::Zero(), viscous = Eigen::Vector3d::Zero();
  double mean_shear = 0.0, max_shear = 0.0;  // |τ_w|, area-weighted mean and maximum
};

struct WallStress {
  std::vector<Eigen::Vector3d> shear;  // per boundary face: triangles, then quadrilaterals
  std::vector<PatchForce> patches;     // in patch id order
};

WallStress wall_stress(const HybridMesh& mesh, const FlowField& flow, double reynolds);

}  // namespace naris::ns
