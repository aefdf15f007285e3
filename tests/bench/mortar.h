#pragma once
// The dissertation's mortar (3.4): a solid cylinder with a hemisphere removed from its top,
// sampled as a signed distance field on an nx × ny × nz grid, generated slice by slice so that
// the mesher's memory bound can be measured.
#include <algorithm>
#include <cmath>

#include "mesh/mve/mve.h"

namespace naris::bench {

class MortarField : public mve::FieldSource {
 public:
  MortarField(int nx, int ny, int nz) {
    frame_.dims = {nx, ny, nz};
    // One voxel is one unit; the cylinder fills 80% of the box across and 80% of its height.
    cx_ = 0.5 * (nx - 1);
    cy_ = 0.5 * (ny - 1);
    radius_ = 0.4 * std::min(nx, ny);
    bottom_ = 0.1 * (nz - 1);
    top_ = 0.9 * (nz - 1);
    bowl_ = 0.7 * radius_;
  }
  const ImageFrame& frame() const override { return frame_; }
  void read_slice(int k, std::span<float> out) const override {
    const int nx = frame_.dims[0], ny = frame_.dims[1];
    const double z = k;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const double r = std::hypot(i - cx_, j - cy_);
        // Inside the cylinder: min of distances to its side, bottom and top.
        const double cylinder = std::min({radius_ - r, z - bottom_, top_ - z});
        // Minus the hemisphere centred on the top face.
        const double bowl = std::sqrt(r * r + (z - top_) * (z - top_)) - bowl_;
        out[static_cast<std::size_t>(j) * nx + i] = static_cast<float>(std::min(cylinder, bowl));
      }
  }

 private:
  ImageFrame frame_;
  double cx_, cy_, radius_, bottom_, top_, bowl_;
};

}  // namespace naris::bench
