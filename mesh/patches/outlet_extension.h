#pragma once
// An outlet extension: a straight tube of the outlet's own section added beyond an outlet cut
// along an image axis. Where the flow turns back through a traction-free outlet the steady
// problem has no unique answer; a few diameters downstream the flow leaves.
#include <string>
#include <vector>

#include "mesh/mve/mve.h"
#include "mesh/patches/patches.h"

namespace naris {

// The image seen through the extension: the kept side of the cut as it is, and beyond the cut's
// voxel plane that plane repeated `voxels` times; what lay beyond the cut is dropped. The
// physical frame is the image's (the origin moves when the tube grows below index 0).
class OutletExtension : public mve::FieldSource {
 public:
  // `options` as prepare_cuts left them for `base` and `cuts`: they say which side of the cut
  // `patch` is kept. Fails when there is no such cut or it is not along an image axis.
  OutletExtension(const mve::FieldSource& base, const std::vector<Cut>& cuts,
                  const mve::MveOptions& options, double length_mm,
                  const std::string& patch = "outlet");

  const ImageFrame& frame() const override { return frame_; }
  void read_slice(int k, std::span<float> out) const override;
  bool binary() const override { return base_.binary(); }

  // The cuts in this frame: the extended one moved to the tube's end, index planes shifted.
  const std::vector<Cut>& cuts() const { return cuts_; }
  int axis() const { return axis_; }
  int voxels() const { return voxels_; }
  double length_mm() const { return voxels_ * frame_.spacing[axis_]; }

 private:
  int source_index(int x) const;

  const mve::FieldSource& base_;
  ImageFrame frame_;
  std::vector<Cut> cuts_;
  int axis_ = 0;
  int voxels_ = 0;
  int shift_ = 0;             // index here − index in the base image, along the axis
  int first_ = 0, last_ = 0;  // the base's voxel planes kept along the axis
  // The base slice being reordered along i or j (FieldSource: one reader at a time).
  mutable std::vector<float> slice_;
};

}  // namespace naris
