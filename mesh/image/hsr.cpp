#include "mesh/image/hsr.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace naris {
namespace {

double sample(const Image2D& im, double x, double y) {
  // Bilinear, with the border extended.
  x = std::clamp(x, 0.0, im.width - 1.0);
  y = std::clamp(y, 0.0, im.height - 1.0);
  const int x0 = std::min(static_cast<int>(x), im.width - 2),
            y0 = std::min(static_cast<int>(y), im.height - 2);
  const double fx = x - x0, fy = y - y0;
  return (1 - fx) * (1 - fy) * im.at(x0, y0) + fx * (1 - fy) * im.at(x0 + 1, y0) +
         (1 - fx) * fy * im.at(x0, y0 + 1) + fx * fy * im.at(x0 + 1, y0 + 1);
}

// Pads to m·2^(L−1) + 1 in each direction (replicating the border) so that every level of the
// pyramid has odd size and halves exactly.
Image2D pad(const Image2D& im, int levels) {
  const int f = 1 << (levels - 1);
  auto size = [&](int n) { return ((n - 1 + f - 1) / f) * f + 1; };
  Image2D out{size(im.width), size(im.height), {}};
  out.v.resize(static_cast<std::size_t>(out.width) * out.height);
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      out.at(x, y) = im.at(std::min(x, im.width - 1), std::min(y, im.height - 1));
  return out;
}

// Eq. 2.14–2.15: the next level is the previous one filtered by [1/4 1/2 1/4] ⊗ [1/4 1/2 1/4]
// and decimated by two.
Image2D reduce(const Image2D& im) {
  Image2D out{(im.width - 1) / 2 + 1, (im.height - 1) / 2 + 1, {}};
  out.v.resize(static_cast<std::size_t>(out.width) * out.height);
  const double w[3] = {0.25, 0.5, 0.25};
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      double s = 0.0;
      for (int r = -1; r <= 1; ++r)
        for (int c = -1; c <= 1; ++c) {
          const int xx = std::clamp(2 * x + c, 0, im.width - 1),
                    yy = std::clamp(2 * y + r, 0, im.height - 1);
          s += w[r + 1] * w[c + 1] * im.at(xx, yy);
        }
      out.at(x, y) = s;
    }
  return out;
}

// Control grid of one level: points every `block` pixels (the last block may be shorter).
struct Grid {
  int nx, ny, block, width, height;
  std::vector<double> u, v;  // at the control points
  Grid(int w, int h, int b) : block(b), width(w), height(h) {
    nx = (w - 1 + b - 1) / b + 1;
    ny = (h - 1 + b - 1) / b + 1;
    u.assign(static_cast<std::size_t>(nx) * ny, 0.0);
    v = u;
  }
  // The bilinear basis: pixel (x, y) lies in cell (cx, cy) with local weights.
  void cell(int x, int y, int& cx, int& cy, double& fx, double& fy) const {
    cx = std::min(x / block, nx - 2);
    cy = std::min(y / block, ny - 2);
    const double bx = std::min(block, width - 1 - cx * block),
                 by = std::min(block, height - 1 - cy * block);
    fx = (x - cx * block) / bx;
    fy = (y - cy * block) / by;
  }
  std::size_t id(int cx, int cy) const { return static_cast<std::size_t>(cy) * nx + cx; }
  void displacement(int x, int y, double& du, double& dv) const {
    int cx, cy;
    double fx, fy;
    cell(x, y, cx, cy, fx, fy);
    const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const std::size_t j[4] = {id(cx, cy), id(cx + 1, cy), id(cx, cy + 1), id(cx + 1, cy + 1)};
    du = dv = 0.0;
    for (int k = 0; k < 4; ++k) du += w[k] * u[j[k]], dv += w[k] * v[j[k]];
  }
};

// One pixel of I2 under the current field: its four control points and bilinear weights, the
// displaced position in I1 and I1's gradient there (central differences): G_i of eq. 2.8.
struct Pixel {
  std::size_t j[4];
  double w[4];
  double px, py, gx, gy;
  Pixel(const Image2D& i1, const Grid& g, int x, int y) {
    int cx, cy;
    double fx, fy;
    g.cell(x, y, cx, cy, fx, fy);
    w[0] = (1 - fx) * (1 - fy), w[1] = fx * (1 - fy), w[2] = (1 - fx) * fy, w[3] = fx * fy;
    j[0] = g.id(cx, cy), j[1] = g.id(cx + 1, cy), j[2] = g.id(cx, cy + 1),
    j[3] = g.id(cx + 1, cy + 1);
    double du = 0, dv = 0;
    for (int k = 0; k < 4; ++k) du += w[k] * g.u[j[k]], dv += w[k] * g.v[j[k]];
    px = x + du;
    py = y + dv;
    gx = 0.5 * (sample(i1, px + 1, py) - sample(i1, px - 1, py));
    gy = 0.5 * (sample(i1, px, py + 1) - sample(i1, px, py - 1));
  }
};

double msd(const Image2D& i1, const Image2D& i2, const Grid& g) {
  double s = 0.0;
  for (int y = 0; y < i2.height; ++y)
    for (int x = 0; x < i2.width; ++x) {
      double du, dv;
      g.displacement(x, y, du, dv);
      const double e = sample(i1, x + du, y + dv) - i2.at(x, y);
      s += e * e;
    }
  return s / static_cast<double>(i2.v.size());
}

// LM iterations of eq. 2.10–2.13 on one level.
void refine(const Image2D& i1, const Image2D& i2, Grid& g, int iterations) {
  const std::size_t n = g.u.size();
  std::vector<double> gu(n), gv(n), huu(n), huv(n), hvv(n), pu(n), pv(n);
  double lambda = 1e-3;
  for (int it = 0; it < iterations; ++it) {
    std::fill(gu.begin(), gu.end(), 0.0);
    std::fill(gv.begin(), gv.end(), 0.0);
    std::fill(huu.begin(), huu.end(), 0.0);
    std::fill(huv.begin(), huv.end(), 0.0);
    std::fill(hvv.begin(), hvv.end(), 0.0);
    double error = 0.0;
    for (int y = 0; y < i2.height; ++y)
      for (int x = 0; x < i2.width; ++x) {
        const Pixel q(i1, g, x, y);
        const auto& j = q.j;
        const auto& w = q.w;
        const double gx = q.gx, gy = q.gy;
        const double e = sample(i1, q.px, q.py) - i2.at(x, y);
        error += e * e;
        for (int k = 0; k < 4; ++k) {
          gu[j[k]] += 2 * e * gx * w[k];  // eq. 2.8
          gv[j[k]] += 2 * e * gy * w[k];
          huu[j[k]] += 2 * gx * gx * w[k] * w[k];  // block_diag(H), eq. 2.9
          huv[j[k]] += 2 * gx * gy * w[k] * w[k];
          hvv[j[k]] += 2 * gy * gy * w[k] * w[k];
        }
      }
    // Preconditioned gradient ĝ = [block_diag(H) + λI]⁻¹ g (eq. 2.12).
    double scale = 0.0;
    for (std::size_t k = 0; k < n; ++k) scale = std::max({scale, huu[k], hvv[k]});
    const double damp = lambda * std::max(scale, 1e-12);
    double gg = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
      const double a = huu[k] + damp, b = huv[k], d = hvv[k] + damp, det = a * d - b * b;
      pu[k] = (d * gu[k] - b * gv[k]) / det;
      pv[k] = (-b * gu[k] + a * gv[k]) / det;
      gg += pu[k] * gu[k] + pv[k] * gv[k];
    }
    if (!(gg > 0.0)) break;
    // ĝᵀHĝ = 2 Σ_i (G_i · d_i)² with d_i the field of ĝ at pixel i (Gauss–Newton H).
    double ghg = 0.0;
    for (int y = 0; y < i2.height; ++y)
      for (int x = 0; x < i2.width; ++x) {
        const Pixel q(i1, g, x, y);
        double qu = 0, qv = 0;
        for (int k = 0; k < 4; ++k) qu += q.w[k] * pu[q.j[k]], qv += q.w[k] * pv[q.j[k]];
        const double gx = q.gx, gy = q.gy;
        ghg += 2 * (gx * qu + gy * qv) * (gx * qu + gy * qv);
      }
    if (!(ghg > 0.0)) break;
    const double alpha = gg / ghg;  // eq. 2.13
    // Δu = −α ĝ, each control point's step capped at one pixel.
    const Grid before = g;
    for (std::size_t k = 0; k < n; ++k) {
      double su = -alpha * pu[k], sv = -alpha * pv[k];
      const double len = std::hypot(su, sv);
      if (len > 1.0) su /= len, sv /= len;
      g.u[k] += su;
      g.v[k] += sv;
    }
    const double now = msd(i1, i2, g) * static_cast<double>(i2.v.size());
    if (now > error) {  // no progress: undo and damp more
      g = before;
      lambda *= 10.0;
    } else {
      // The damping never drops below 0.3 of the largest block: control points whose support
      // barely touches an edge have nearly singular blocks, and without a floor their
      // preconditioned steps run away even with the one-pixel cap; 0.3 still lets the
      // two-squares test register exactly (docs/results/solver-choices.md).
      lambda = std::max(lambda / 10.0, 0.3);
    }
  }
}

}  // namespace

Displacement register_hsr(const Image2D& i1, const Image2D& i2, const HsrOptions& o) {
  if (i1.width != i2.width || i1.height != i2.height)
    fail("HSR: slices of different size ({}×{} and {}×{})", i1.width, i1.height, i2.width,
         i2.height);
  if (i1.width < 2 || i1.height < 2) fail("HSR: slices must be at least 2×2 pixels");
  if (o.levels < 1 || o.block < 1 || o.iterations < 0)
    fail("HSR: levels and block must be positive");
  std::vector<Image2D> p1{pad(i1, o.levels)}, p2{pad(i2, o.levels)};
  for (int l = 1; l < o.levels; ++l) {
    p1.push_back(reduce(p1.back()));
    p2.push_back(reduce(p2.back()));
  }
  // Coarse to fine: each level starts from the coarser field, doubled.
  Grid g(p1.back().width, p1.back().height, o.block);
  for (int l = o.levels - 1; l >= 0; --l) {
    if (l != o.levels - 1) {
      Grid fine(p1[l].width, p1[l].height, o.block);
      for (int cy = 0; cy < fine.ny; ++cy)
        for (int cx = 0; cx < fine.nx; ++cx) {
          const int x = std::min(cx * o.block, fine.width - 1),
                    y = std::min(cy * o.block, fine.height - 1);
          double du, dv;
          g.displacement(std::min(x / 2, g.width - 1), std::min(y / 2, g.height - 1), du, dv);
          fine.u[fine.id(cx, cy)] = 2 * du;
          fine.v[fine.id(cx, cy)] = 2 * dv;
        }
      g = fine;
    }
    refine(p1[l], p2[l], g, o.iterations);
  }
  Displacement d;
  d.u = Image2D{i1.width, i1.height, std::vector<double>(i1.v.size())};
  d.v = d.u;
  for (int y = 0; y < i1.height; ++y)
    for (int x = 0; x < i1.width; ++x) g.displacement(x, y, d.u.at(x, y), d.v.at(x, y));
  double s = 0.0;
  for (int y = 0; y < i2.height; ++y)
    for (int x = 0; x < i2.width; ++x) {
      const double e = sample(i1, x + d.u.at(x, y), y + d.v.at(x, y)) - i2.at(x, y);
      s += e * e;
    }
  d.msd = s / static_cast<double>(i2.v.size());
  return d;
}

Image2D interpolate_hsr(const Image2D& i1, const Image2D& i2, const Displacement& d, double s) {
  // A point y of the intermediate slice came from x = y − s·u(x) in I2 and goes to x + u in I1;
  // with a smooth field, u(x) ≈ u(y), which gives a backward map from both sides.
  Image2D out{i1.width, i1.height, std::vector<double>(i1.v.size())};
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x) {
      // Fixed-point iteration for the source x with x + s·u(x) = y.
      double sx = x, sy = y;
      for (int it = 0; it < 10; ++it) {
        const double du = sample(d.u, sx, sy), dv = sample(d.v, sx, sy);
        sx = x - s * du;
        sy = y - s * dv;
      }
      const double du = sample(d.u, sx, sy), dv = sample(d.v, sx, sy);
      out.at(x, y) = (1 - s) * sample(i2, sx, sy) + s * sample(i1, sx + du, sy + dv);
    }
  return out;
}

Image2D interpolate_linear(const Image2D& i1, const Image2D& i2, double s) {
  Image2D out = i2;
  for (std::size_t k = 0; k < out.v.size(); ++k) out.v[k] = (1 - s) * i2.v[k] + s * i1.v[k];
  return out;
}

namespace {

// Squared Euclidean distance transform along one line (Felzenszwalb & Huttenlocher 2012): the
// lower envelope of parabolas rooted at the samples of f (0 on features, a large value elsewhere).
void distance_1d(const double* f, int n, std::ptrdiff_t stride, double* out, std::vector<int>& v,
                 std::vector<double>& z) {
  v.assign(static_cast<std::size_t>(n), 0);
  z.assign(static_cast<std::size_t>(n) + 1, 0.0);
  int k = 0;
  z[0] = -std::numeric_limits<double>::infinity();
  z[1] = std::numeric_limits<double>::infinity();
  auto fv = [&](int q) { return f[q * stride]; };
  for (int q = 1; q < n; ++q) {
    // z[0] = −∞ ends the loop: the parabola of v[0] is never removed from the left.
    auto meet = [&](int p) {
      return ((fv(q) + double(q) * q) - (fv(p) + double(p) * p)) / (2.0 * (q - p));
    };
    double s = meet(v[static_cast<std::size_t>(k)]);
    while (s <= z[static_cast<std::size_t>(k)]) {
      --k;
      s = meet(v[static_cast<std::size_t>(k)]);
    }
    ++k;
    v[static_cast<std::size_t>(k)] = q;
    z[static_cast<std::size_t>(k)] = s;
    z[static_cast<std::size_t>(k) + 1] = std::numeric_limits<double>::infinity();
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[static_cast<std::size_t>(k) + 1] < q) ++k;
    const int p = v[static_cast<std::size_t>(k)];
    out[q * stride] = double(q - p) * (q - p) + fv(p);
  }
}

// Distance (pixels) from every pixel to the nearest pixel where `feature` holds.
std::vector<double> distance_to(const Image2D& im, bool inside_feature) {
  const int w = im.width, h = im.height;
  const double far = 4.0 * (double(w) * w + double(h) * h) + 1.0;
  std::vector<double> f(im.v.size()), g(im.v.size());
  for (std::size_t k = 0; k < im.v.size(); ++k)
    f[k] = (im.v[k] > 0.5) == inside_feature ? 0.0 : far;
  std::vector<int> v;
  std::vector<double> z, line(static_cast<std::size_t>(std::max(w, h)));
  for (int x = 0; x < w; ++x) distance_1d(f.data() + x, h, w, g.data() + x, v, z);
  for (int y = 0; y < h; ++y) {
    distance_1d(g.data() + static_cast<std::ptrdiff_t>(y) * w, w, 1, line.data(), v, z);
    for (int x = 0; x < w; ++x) f[static_cast<std::size_t>(y) * w + x] = std::sqrt(line[x]);
  }
  return f;
}

}  // namespace

Image2D signed_distance(const Image2D& mask) {
  // Half a pixel from each side puts the zero level on the boundary between the two sets.
  const std::vector<double> to_out = distance_to(mask, false), to_in = distance_to(mask, true);
  Image2D out{mask.width, mask.height, std::vector<double>(mask.v.size(), 0.0)};
  const bool any_in = std::any_of(mask.v.begin(), mask.v.end(), [](double x) { return x > 0.5; });
  const bool any_out = std::any_of(mask.v.begin(), mask.v.end(), [](double x) { return x <= 0.5; });
  const double none = std::max(mask.width, mask.height);
  for (std::size_t k = 0; k < out.v.size(); ++k)
    out.v[k] =
        mask.v[k] > 0.5 ? (any_out ? to_out[k] - 0.5 : none) : (any_in ? -(to_in[k] - 0.5) : -none);
  return out;
}

Image2D interpolate_signed_distance(const Image2D& d1, const Image2D& d2, double s) {
  Image2D out = d2;
  for (std::size_t k = 0; k < out.v.size(); ++k)
    out.v[k] = (1 - s) * d2.v[k] + s * d1.v[k] > 0.0 ? 1.0 : 0.0;
  return out;
}

Image2D interpolate_shape(const Image2D& i1, const Image2D& i2, double s) {
  return interpolate_signed_distance(signed_distance(i1), signed_distance(i2), s);
}

}  // namespace naris
