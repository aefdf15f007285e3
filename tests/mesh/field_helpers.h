#pragma once
// Fields in memory for the mesher tests.
#include <vector>

#include "mesh/mve/mve.h"

namespace naris::testing {

class ArrayField : public mve::FieldSource {
 public:
  ArrayField(int nx, int ny, int nz) {
    frame_.dims = {nx, ny, nz};
    values_.assign(frame_.voxel_count(), -1.0f);
  }
  float& at(int i, int j, int k) { return values_[frame_.index(i, j, k)]; }
  ImageFrame& mutable_frame() { return frame_; }
  const ImageFrame& frame() const override { return frame_; }
  void read_slice(int k, std::span<float> out) const override {
    const std::size_t n = static_cast<std::size_t>(frame_.dims[0]) * frame_.dims[1];
    std::copy_n(values_.begin() + static_cast<std::ptrdiff_t>(n * k), n, out.begin());
  }

 private:
  ImageFrame frame_;
  std::vector<float> values_;
};

// Volume enclosed by the boundary faces (divergence theorem): independent of the cells.
inline double boundary_volume(const HybridMesh& m) {
  double v = 0.0;
  for (const auto& t : m.boundary_tris)
    v += m.nodes[t[0]].dot(m.nodes[t[1]].cross(m.nodes[t[2]])) / 6.0;
  for (const auto& q : m.boundary_quads) {
    v += m.nodes[q[0]].dot(m.nodes[q[1]].cross(m.nodes[q[2]])) / 6.0;
    v += m.nodes[q[0]].dot(m.nodes[q[2]].cross(m.nodes[q[3]])) / 6.0;
  }
  return v;
}

// A volume of nx × ny × nz voxels (unit spacing, origin 0) holding value(i, j, k).
template <class T, class F>
Volume<T> sampled_volume(int nx, int ny, int nz, F&& value) {
  Volume<T> v;
  v.frame.dims = {nx, ny, nz};
  v.values.resize(v.frame.voxel_count());
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) v.at(i, j, k) = static_cast<T>(value(i, j, k));
  return v;
}

inline mve::MveOptions quiet_options() {
  mve::MveOptions o;
  o.keep_largest_component = false;
  return o;
}

}  // namespace naris::testing
