#include "mesh/image/interpolate_slices.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>

#include "core/error.h"
#include "core/parallel.h"

namespace naris {
namespace {

// In-slice axes for a slice across `axis`, in increasing order.
std::pair<int, int> plane_axes(int axis) {
  return axis == 0 ? std::pair{1, 2} : axis == 1 ? std::pair{0, 2} : std::pair{0, 1};
}

}  // namespace

SliceMethod parse_slice_method(const std::string& name) {
  if (name == "hsr") return SliceMethod::hsr;
  if (name == "linear") return SliceMethod::linear;
  if (name == "shape") return SliceMethod::shape;
  fail("unknown interpolation method '{}' (hsr, linear or shape)", name);
}

namespace {

// Calls f(x, y, i, j, k) for every pixel (x, y) of the slice across `axis` at `index`.
template <class F>
void for_each_in_slice(const std::array<int, 3>& dims, int axis, int index, F&& f) {
  const auto [a, b] = plane_axes(axis);
  std::array<int, 3> ijk{};
  ijk[axis] = index;
  for (int y = 0; y < dims[b]; ++y)
    for (int x = 0; x < dims[a]; ++x) {
      ijk[a] = x;
      ijk[b] = y;
      f(x, y, ijk[0], ijk[1], ijk[2]);
    }
}

// The volume with k new slices between each pair along `axis`, zero-filled.
Volume<float> interpolated_grid(const Volume<float>& v, int axis, int k) {
  if (axis < 0 || axis > 2) fail("slice axis must be 0, 1 or 2 (i, j or k)");
  if (k < 0) fail("the number of slices to insert must not be negative");
  const int n = v.dims()[axis];
  if (n < 2) fail("a volume with a single slice along axis {} cannot be interpolated", axis);
  Volume<float> out;
  out.frame = v.frame;
  out.frame.dims[axis] = (n - 1) * (k + 1) + 1;
  out.frame.spacing[axis] /= (k + 1);
  out.values.assign(out.frame.voxel_count(), 0.0f);
  return out;
}

// pair(p) for every pair of consecutive slices p, p + 1, shared among `threads` threads.
template <class F>
void for_each_slice_pair(int pairs, int threads, F&& pair) {
  std::atomic<int> next{0};
  run_threads(thread_count(threads), [&](unsigned, unsigned) {
    for (int p; (p = next++) < pairs;) pair(p);
  });
}

}  // namespace

Image2D slice_across(const Volume<float>& v, int axis, int index) {
  const auto [a, b] = plane_axes(axis);
  Image2D im{v.dims()[a], v.dims()[b], {}};
  im.v.resize(static_cast<std::size_t>(im.width) * im.height);
  for_each_in_slice(v.dims(), axis, index,
                    [&](int x, int y, int i, int j, int k) { im.at(x, y) = v.at(i, j, k); });
  return im;
}

void set_slice_across(Volume<float>& v, int axis, int index, const Image2D& im) {
  for_each_in_slice(v.dims(), axis, index, [&](int x, int y, int i, int j, int k) {
    v.at(i, j, k) = static_cast<float>(im.at(x, y));
  });
}

std::vector<float> map_labels(const Volume<float>& v) {
  std::array<bool, 256> seen{};
  for (float x : v.values) {
    if (!(x >= 0.0f && x <= 255.0f) || x != std::floor(x)) return {};
    seen[static_cast<std::size_t>(x)] = true;
  }
  std::vector<float> labels;
  for (int l = 1; l < 256; ++l)
    if (seen[static_cast<std::size_t>(l)]) labels.push_back(static_cast<float>(l));
  if (labels.size() < 2) labels.clear();
  return labels;
}

Volume<float> interpolate_label_map(const Volume<float>& v, const std::vector<float>& labels,
                                    int axis, int k, int threads) {
  Volume<float> out = interpolated_grid(v, axis, k);
  const int n = v.dims()[axis];
  auto mask_of = [](const Image2D& im, double label) {
    Image2D m = im;
    for (double& x : m.v) x = x == label ? 1.0 : 0.0;
    return m;
  };
  for_each_slice_pair(n - 1, threads, [&](int p) {
    std::vector<Image2D> da(labels.size()), db(labels.size());
    const Image2D a = slice_across(v, axis, p), b = slice_across(v, axis, p + 1);
    set_slice_across(out, axis, p * (k + 1), a);
    if (p + 1 == n - 1) set_slice_across(out, axis, (p + 1) * (k + 1), b);
    if (k == 0) return;
    for (std::size_t l = 0; l < labels.size(); ++l) {
      da[l] = signed_distance(mask_of(a, labels[l]));
      db[l] = signed_distance(mask_of(b, labels[l]));
    }
    for (int q = 1; q <= k; ++q) {
      const double s = static_cast<double>(q) / (k + 1);
      Image2D im{a.width, a.height, std::vector<double>(a.v.size(), 0.0)};
      for (std::size_t px = 0; px < im.v.size(); ++px) {
        double best = 0.0;
        for (std::size_t l = 0; l < labels.size(); ++l) {
          const double d = (1 - s) * da[l].v[px] + s * db[l].v[px];
          if (d > best) best = d, im.v[px] = labels[l];
        }
      }
      set_slice_across(out, axis, p * (k + 1) + q, im);
    }
  });
  return out;
}

Volume<float> interpolate_slices(const Volume<float>& v, int axis, int k, SliceMethod method,
                                 const HsrOptions& hsr, int threads) {
  Volume<float> out = interpolated_grid(v, axis, k);
  const int n = v.dims()[axis];
  const bool mask = is_binary(v);
  for_each_slice_pair(n - 1, threads, [&](int p) {
    const Image2D a = slice_across(v, axis, p), b = slice_across(v, axis, p + 1);
    set_slice_across(out, axis, p * (k + 1), a);
    if (p + 1 == n - 1) set_slice_across(out, axis, (p + 1) * (k + 1), b);
    // I2 is the lower slice (s = 0), I1 the upper (s = 1).
    Displacement d;
    if (method == SliceMethod::hsr && k > 0) d = register_hsr(b, a, hsr);
    Image2D da, db;  // signed distance maps, once per pair
    if (method == SliceMethod::shape && k > 0) {
      da = signed_distance(a);
      db = signed_distance(b);
    }
    for (int q = 1; q <= k; ++q) {
      const double s = static_cast<double>(q) / (k + 1);
      Image2D im = method == SliceMethod::hsr      ? interpolate_hsr(b, a, d, s)
                   : method == SliceMethod::linear ? interpolate_linear(b, a, s)
                                                   : interpolate_signed_distance(db, da, s);
      if (mask && method != SliceMethod::shape)
        for (double& x : im.v) x = x > 0.5 ? 1.0 : 0.0;
      set_slice_across(out, axis, p * (k + 1) + q, im);
    }
  });
  return out;
}

}  // namespace naris
