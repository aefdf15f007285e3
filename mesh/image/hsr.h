#pragma once
// Hierarchical spline-based registration (HSR, dissertation ch. 2) for slice interpolation:
// a displacement field on a control grid of fixed block size with a bilinear basis (eq. 2.4–2.5)
// registers slice I1 onto slice I2 by minimizing the mean squared difference (eq. 2.6) with a
// Levenberg–Marquardt variant (block-diagonal preconditioned gradient, optimal step, eq.
// 2.10–2.13, steps capped at one pixel), coarse to fine on Gaussian pyramids (eq. 2.14–2.15).
// Intermediate slices come from the interpolated displacement field. Linear (cross-fade) and
// shape-based (signed-distance) interpolation are kept as baselines.
#include <vector>

namespace naris {

struct Image2D {
  int width = 0, height = 0;
  std::vector<double> v;  // row-major, x fastest
  double at(int x, int y) const { return v[static_cast<std::size_t>(y) * width + x]; }
  double& at(int x, int y) { return v[static_cast<std::size_t>(y) * width + x]; }
};

struct HsrOptions {
  int block = 8;        // control-grid spacing in pixels, the same at every level
  int levels = 4;       // pyramid levels (1: the original image only)
  int iterations = 30;  // LM iterations per level
};

// Displacement (u, v) at every pixel of I2 such that I1(x + u, y + v) ≈ I2(x, y).
struct Displacement {
  Image2D u, v;
  double msd = 0.0;  // final mean squared difference
};

Displacement register_hsr(const Image2D& i1, const Image2D& i2, const HsrOptions& options = {});

// The slice at fraction s ∈ [0, 1] from I2 (s = 0) to I1 (s = 1) along the displacement field.
Image2D interpolate_hsr(const Image2D& i1, const Image2D& i2, const Displacement& d, double s);
Image2D interpolate_linear(const Image2D& i1, const Image2D& i2, double s);
// Shape-based: signed distance maps of the masks (value > 0.5) interpolated linearly.
Image2D interpolate_shape(const Image2D& i1, const Image2D& i2, double s);
// Signed Euclidean distance (pixels) to the boundary of a mask (value > 0.5), positive inside:
// exact, linear time (separable transform). The shape-based blend of two such maps at s.
Image2D signed_distance(const Image2D& mask);
Image2D interpolate_signed_distance(const Image2D& d1, const Image2D& d2, double s);

}  // namespace naris
