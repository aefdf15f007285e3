#include "mesh/image/resample.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace naris {

Volume<float> decimate_in_plane(const Volume<float>& v, int factor) {
  if (factor < 1) fail("decimation factor {} must be a positive integer", factor);
  if (factor == 1) return v;
  const auto& d = v.dims();
  Volume<float> out;
  out.frame = v.frame;
  out.frame.dims = {d[0] / factor, d[1] / factor, d[2]};
  if (out.frame.dims[0] < 2 || out.frame.dims[1] < 2)
    fail("decimation by {} leaves fewer than two voxels in a slice ({}×{})", factor, d[0], d[1]);
  out.frame.spacing[0] *= factor;
  out.frame.spacing[1] *= factor;
  // The first output voxel is the centre of the first block.
  out.frame.origin = v.frame.physical(Eigen::Vector3d(0.5 * (factor - 1), 0.5 * (factor - 1), 0.0));
  out.values.assign(out.frame.voxel_count(), 0.0f);
  const float scale = 1.0f / static_cast<float>(factor * factor);
  for (int k = 0; k < out.frame.dims[2]; ++k)
    for (int j = 0; j < out.frame.dims[1]; ++j)
      for (int i = 0; i < out.frame.dims[0]; ++i) {
        float sum = 0.0f;
        for (int b = 0; b < factor; ++b)
          for (int a = 0; a < factor; ++a) sum += v.at(i * factor + a, j * factor + b, k);
        out.at(i, j, k) = sum * scale;
      }
  return out;
}

Volume<float> rotate_about_axis(const Volume<float>& v, int axis, double degrees, float fill) {
  if (axis < 0 || axis > 2) fail("rotation axis must be i, j or k");
  const double r = degrees * M_PI / 180.0;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  // Rotation in index space about the centre (spacing is handled by working in millimetres).
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();
  rot(a1, a1) = std::cos(r), rot(a1, a2) = -std::sin(r);
  rot(a2, a1) = std::sin(r), rot(a2, a2) = std::cos(r);
  const Eigen::Matrix3d d = v.frame.direction * rot;  // the new grid's axes, physical
  const auto& dims = v.dims();
  const Eigen::Vector3d centre =
      v.frame.physical(Eigen::Vector3d(dims[0] - 1, dims[1] - 1, dims[2] - 1) / 2.0);
  // Extent of the old volume's corners along the new axes.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner(c & 1 ? dims[0] - 1 : 0, c & 2 ? dims[1] - 1 : 0,
                                 c & 4 ? dims[2] - 1 : 0);
    const Eigen::Vector3d q = d.transpose() * (v.frame.physical(corner) - centre);
    lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
  }
  Volume<float> out;
  out.frame.direction = d;
  out.frame.spacing = v.frame.spacing;
  for (int a = 0; a < 3; ++a)
    out.frame.dims[a] =
        static_cast<int>(std::floor((hi[a] - lo[a]) / v.frame.spacing[a] + 1e-9)) + 1;
  out.frame.origin = centre + d * lo;
  out.values.assign(out.frame.voxel_count(), fill);
  const Eigen::Matrix3d to_old = v.frame.index_to_physical().inverse();
  for (int k = 0; k < out.frame.dims[2]; ++k)
    for (int j = 0; j < out.frame.dims[1]; ++j)
      for (int i = 0; i < out.frame.dims[0]; ++i) {
        const Eigen::Vector3d p =
            to_old * (out.frame.physical(Eigen::Vector3d(i, j, k)) - v.frame.origin);
        const int i0 = static_cast<int>(std::floor(p[0])), j0 = static_cast<int>(std::floor(p[1])),
                  k0 = static_cast<int>(std::floor(p[2]));
        if (i0 < 0 || j0 < 0 || k0 < 0 || i0 + 1 > dims[0] - 1 || j0 + 1 > dims[1] - 1 ||
            k0 + 1 > dims[2] - 1) {
          // On the last plane exactly: clamp instead of dropping.
          if (p.minCoeff() < -1e-9 || p[0] > dims[0] - 1 + 1e-9 || p[1] > dims[1] - 1 + 1e-9 ||
              p[2] > dims[2] - 1 + 1e-9)
            continue;
        }
        const int ia = std::clamp(i0, 0, dims[0] - 2), ja = std::clamp(j0, 0, dims[1] - 2),
                  ka = std::clamp(k0, 0, dims[2] - 2);
        const double fx = p[0] - ia, fy = p[1] - ja, fz = p[2] - ka;
        double s = 0.0;
        for (int c = 0; c < 8; ++c) {
          const double w = (c & 1 ? fx : 1 - fx) * (c & 2 ? fy : 1 - fy) * (c & 4 ? fz : 1 - fz);
          s += w * v.at(ia + (c & 1), ja + ((c >> 1) & 1), ka + ((c >> 2) & 1));
        }
        out.at(i, j, k) = static_cast<float>(s);
      }
  return out;
}

}  // namespace naris
