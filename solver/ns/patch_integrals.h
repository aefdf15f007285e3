#pragma once
// Integrals of nodal fields over a boundary patch, face by face: the flux through inlets and
// outlets (exact for the cells' traces, linear on triangles and bilinear on quadrilaterals), mean
// pressures (each face's area times the mean of its corners); the momentum flux by a rule exact
// for the product of two linear fields.
#include <vector>

#include "mesh/hybrid_mesh.h"

namespace naris::ns {

// ∫ u·n dA over one boundary face `v` (n outward).
double face_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u,
                 std::span<const NodeId> v);
// ∫ u·n dA over the faces of `patch` (n outward).
double patch_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u, int patch);
// ∫ u (u·n) dA over the faces of `patch` (n outward): the momentum the flow carries out.
Eigen::Vector3d patch_momentum_flux(const HybridMesh& mesh, const std::vector<Eigen::Vector3d>& u,
                                    int patch);
// ∫ v dA and the area of the faces of `patch` (summed over ranks, these give the mean).
struct PatchIntegral {
  double integral = 0.0, area = 0.0;
};
PatchIntegral patch_integral(const HybridMesh& mesh, const std::vector<double>& values, int patch);

}  // namespace naris::ns
