#pragma once
// A 3D image on a regular grid with its physical frame: x = origin + D·diag(spacing)·(i,j,k).
// Index ↔ physical conversion lives here and nowhere else. Physical coordinates are patient
// LPS millimetres (DICOM's and 3D Slicer's convention); readers of RAS formats convert.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace naris {

struct ImageFrame {
  std::array<int, 3> dims{0, 0, 0};
  Eigen::Vector3d spacing = Eigen::Vector3d::Ones();
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Matrix3d direction = Eigen::Matrix3d::Identity();  // orthonormal columns

  std::size_t voxel_count() const {
    return static_cast<std::size_t>(dims[0]) * dims[1] * static_cast<std::size_t>(dims[2]);
  }
  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims[0]) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims[1]) * k);
  }
  Eigen::Matrix3d index_to_physical() const { return direction * spacing.asDiagonal(); }
  Eigen::Vector3d physical(const Eigen::Vector3d& ijk) const {
    return origin + index_to_physical() * ijk;
  }
  Eigen::Vector3d continuous_index(const Eigen::Vector3d& x) const {
    return index_to_physical().inverse() * (x - origin);
  }
};

template <class T>
struct Volume {
  ImageFrame frame;
  std::vector<T> values;

  const std::array<int, 3>& dims() const { return frame.dims; }
  T& at(int i, int j, int k) { return values[frame.index(i, j, k)]; }
  const T& at(int i, int j, int k) const { return values[frame.index(i, j, k)]; }
  std::span<const T> slice(int k) const {
    const std::size_t n = static_cast<std::size_t>(frame.dims[0]) * frame.dims[1];
    return {values.data() + n * static_cast<std::size_t>(k), n};
  }
};

// True when every value is 0 or 1: a labelmap read as floats.
inline bool is_binary(const Volume<float>& v) {
  return std::all_of(v.values.begin(), v.values.end(),
                     [](float x) { return x == 0.0f || x == 1.0f; });
}

// The 0/1 mask of the voxels above one half, on the same frame.
inline Volume<std::uint8_t> to_mask(const Volume<float>& v) {
  Volume<std::uint8_t> m;
  m.frame = v.frame;
  m.values.resize(v.values.size());
  std::transform(v.values.begin(), v.values.end(), m.values.begin(),
                 [](float x) { return static_cast<std::uint8_t>(x > 0.5f); });
  return m;
}

}  // namespace naris
