#include "mesh/image/smooth_label.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "mesh/image/distance_transform.h"
#include "mesh/image/grid_lines.h"

namespace naris {
namespace {

// Gaussian smoothing along one axis in place, the border value repeated beyond the volume.
void smooth_axis(Volume<float>& v, int axis, double sigma_voxels, int threads) {
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma_voxels)));
  std::vector<double> kernel(static_cast<std::size_t>(2 * radius + 1));
  double sum = 0.0;
  for (int t = -radius; t <= radius; ++t)
    sum += kernel[static_cast<std::size_t>(t + radius)] =
        std::exp(-0.5 * t * t / (sigma_voxels * sigma_voxels));
  for (double& k : kernel) k /= sum;
  transform_lines(v.frame, v.values, axis, threads, [&] {
    return [&, copy = std::vector<float>()](std::span<float> line) mutable {
      copy.assign(line.begin(), line.end());
      const int last = static_cast<int>(line.size()) - 1;
      for (int x = 0; x <= last; ++x) {
        double s = 0.0;
        for (int d = -radius; d <= radius; ++d)
          s += kernel[static_cast<std::size_t>(d + radius)] *
               copy[static_cast<std::size_t>(std::clamp(x + d, 0, last))];
        line[static_cast<std::size_t>(x)] = static_cast<float>(s);
      }
    };
  });
}

// Smoothing a distance moves its level zero towards the concave side by σ²/2 times its
// Laplacian (σ²/R inside a sphere of radius R); one step of the heat equation backwards,
// φ − (σ²/2) Δφ, puts it back where the curvature is smooth. σ in mm.
void undo_shrinkage(Volume<float>& field, double sigma_mm) {
  const auto& d = field.frame.dims;
  const Eigen::Vector3d& sp = field.frame.spacing;
  const double half_sigma2 = 0.5 * sigma_mm * sigma_mm;
  std::vector<float> corrected(field.values);
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i) {
        const std::size_t q = field.frame.index(i, j, k);
        const int c[3] = {i, j, k};
        double laplacian = 0.0;
        for (int a = 0; a < 3; ++a) {
          if (d[a] < 3) continue;
          int lo[3] = {i, j, k}, hi[3] = {i, j, k};
          lo[a] = std::max(0, c[a] - 1), hi[a] = std::min(d[a] - 1, c[a] + 1);
          laplacian +=
              (field.values[field.frame.index(lo[0], lo[1], lo[2])] - 2.0 * field.values[q] +
               field.values[field.frame.index(hi[0], hi[1], hi[2])]) /
              (sp[a] * sp[a]);
        }
        corrected[q] = static_cast<float>(field.values[q] - half_sigma2 * laplacian);
      }
  field.values = std::move(corrected);
}

}  // namespace

Volume<float> smooth_label_field(const Volume<std::uint8_t>& mask, const SmoothLabelOptions& o) {
  if (!(o.sigma > 0.0)) fail("the smoothing width must be positive (voxels)");
  if (!(o.margin > 0.0 && o.margin < 0.5)) fail("the smoothing margin must lie in (0, 0.5) voxel");
  const std::size_t n = mask.values.size();
  std::vector<std::uint8_t> inside(n), outside(n);
  std::size_t count = 0;
  for (std::size_t q = 0; q < n; ++q) {
    inside[q] = mask.values[q] != 0;
    outside[q] = !inside[q];
    count += inside[q];
  }
  if (count == 0 || count == n)
    fail("the labelmap is {}: it has no wall to smooth", count == 0 ? "empty" : "full");
  // Signed distance (mm), positive inside; the wall lies half a voxel from the centres beside it.
  const std::vector<float> to_out =
      squared_distance(mask.frame, outside, OutsideIs::nothing, o.threads);
  const std::vector<float> to_in =
      squared_distance(mask.frame, inside, OutsideIs::nothing, o.threads);
  const double h = mask.frame.spacing.minCoeff();
  Volume<float> field;
  field.frame = mask.frame;
  field.values.resize(n);
  for (std::size_t q = 0; q < n; ++q)
    field.values[q] = static_cast<float>(inside[q] ? std::sqrt(to_out[q]) - 0.5 * h
                                                   : -(std::sqrt(to_in[q]) - 0.5 * h));
  for (int axis = 0; axis < 3; ++axis)
    if (mask.frame.dims[axis] > 1)  // isotropic in millimetres: σ voxels of the finest axis
      smooth_axis(field, axis, o.sigma * h / mask.frame.spacing[axis], o.threads);
  undo_shrinkage(field, o.sigma * h);
  // Each voxel stays on its own side, `margin` of a voxel from the level zero.
  const auto m = static_cast<float>(o.margin * h);
  for (std::size_t q = 0; q < n; ++q)
    field.values[q] = inside[q] ? std::max(field.values[q], m) : std::min(field.values[q], -m);
  return field;
}

}  // namespace naris
