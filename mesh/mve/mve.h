#pragma once
// Marching volume elements (dissertation ch. 3): a conforming hybrid mesh straight from a
// scalar field on a regular grid — hexahedra for cubes wholly inside, tetrahedra and pyramids
// in cubes the surface cuts. The volume is streamed slab by slab: besides the output mesh, the
// mesher holds two slices of the field and the node maps of two slices.
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "mesh/hybrid_mesh.h"
#include "mesh/image/inside_rule.h"
#include "mesh/image/volume.h"
#include "mesh/quality/level_set.h"

namespace naris::mve {

// A scalar field sampled on a grid; inside where the value is > 0. Slices are along the third
// index (k), each nx·ny values with i fastest, read by one thread at a time.
class FieldSource {
 public:
  virtual ~FieldSource() = default;
  virtual const ImageFrame& frame() const = 0;
  virtual void read_slice(int k, std::span<float> out) const = 0;
  // True when every value is +1 or -1 (a labelmap): every isopoint is then an edge midpoint.
  virtual bool binary() const { return false; }
};

// The box of voxels to mesh (inclusive index bounds). Cube faces on its sides close the object
// where it touches them; those faces go to the side's patch.
struct CropBox {
  std::array<int, 3> lo{0, 0, 0};
  std::array<int, 3> hi{-1, -1, -1};  // -1: the last voxel
};

// A half-space kept by the mesher: g(ijk) = normal·ijk + offset > 0, in voxel-index space.
// Where it cuts the object, isopoints are placed exactly on the plane (the crossing of the
// minimum of two linear interpolants is the smaller of their crossings).
struct ClipPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;
  double operator()(const Eigen::Vector3d& ijk) const { return normal.dot(ijk) + offset; }
};

struct MveOptions {
  CropBox crop;
  std::vector<ClipPlane> clip_planes;
  // Patch names of the six sides of the box: −i, +i, −j, +j, −k, +k.
  std::array<std::string, 6> side_patch{"imin", "imax", "jmin", "jmax", "kmin", "kmax"};
  std::string wall_patch = "wall";
  // Isopoints keep at least this fraction of an edge from its vertices so that no cell is flat.
  double isopoint_margin = 1e-3;
  bool keep_largest_component = true;
};

struct MveStats {
  std::size_t unresolved_cubes = 0;  // no candidate gave positive volumes (should stay 0)
  std::size_t components = 0;        // connected mesh components before filtering
  std::size_t dropped_components = 0;
  std::size_t dropped_cells = 0;
};

// Meshes the inside of the field in physical coordinates (mm). Throws naris::Error when nothing
// is inside.
HybridMesh march_volume_elements(const FieldSource& field, const MveOptions& options,
                                 MveStats* stats = nullptr);

// A FieldSource over a volume in memory: inside by `rule` (below or above a threshold, or equal
// to a label). As a LevelSet it is the trilinear interpolant of the same values inside the
// image: the surface on which MVE's isopoints lie (linear along the grid's edges).
class VolumeField : public FieldSource, public LevelSet {
 public:
  VolumeField(const Volume<float>& volume, InsideRule rule, double level);
  const ImageFrame& frame() const override { return volume_.frame; }
  void read_slice(int k, std::span<float> out) const override;
  bool binary() const override { return rule_ == InsideRule::label; }
  bool evaluate(const Eigen::Vector3d& x, double& value, Eigen::Vector3d& gradient) const override;

 private:
  float value(std::size_t voxel) const;

  const Volume<float>& volume_;
  InsideRule rule_;
  float level_;
  Eigen::Matrix3d to_index_;  // physical offset → continuous index
};

}  // namespace naris::mve
