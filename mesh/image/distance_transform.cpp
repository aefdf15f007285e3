#include "mesh/image/distance_transform.h"

#include <cmath>
#include <limits>

#include "mesh/image/grid_lines.h"

namespace naris {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// One line: d[x] = min_q (f[q] + (s·(x−q))²), with virtual targets at q = −1 and q = n when
// the outside is a target. v, z are the envelope's parabola sites and boundaries (n + 3 each).
void transform_line(std::span<float> f, double s, bool outside_target, std::vector<double>& d,
                    std::vector<int>& v, std::vector<double>& z) {
  const int n = static_cast<int>(f.size());
  auto value = [&](int q) { return q < 0 || q >= n ? 0.0 : static_cast<double>(f[q]); };
  const double s2 = s * s;
  int k = -1;
  auto add = [&](int q) {
    const double fq = value(q);
    if (!std::isfinite(fq)) return;
    while (k >= 0) {
      const int p = v[k];
      // Where the parabolas of p and q meet.
      const double meet = ((fq + s2 * q * q) - (value(p) + s2 * p * p)) / (2.0 * s2 * (q - p));
      if (meet > z[k]) {
        v[++k] = q;
        z[k] = meet;
        return;
      }
      --k;
    }
    v[++k] = q;
    z[k] = -std::numeric_limits<double>::infinity();
  };
  if (outside_target) add(-1);
  for (int q = 0; q < n; ++q) add(q);
  if (outside_target) add(n);
  if (k < 0) return;  // no finite value on the line: it stays +inf
  int j = 0;
  for (int x = 0; x < n; ++x) {
    while (j < k && z[j + 1] < x) ++j;
    const double dx = s * (x - v[j]);
    d[x] = value(v[j]) + dx * dx;
  }
  for (int x = 0; x < n; ++x) f[x] = static_cast<float>(d[x]);
}

}  // namespace

std::vector<float> squared_distance(const ImageFrame& frame, std::span<const std::uint8_t> target,
                                    OutsideIs outside, int threads) {
  std::vector<float> dist(target.size());
  for (std::size_t q = 0; q < target.size(); ++q) dist[q] = target[q] ? 0.0f : kInf;
  const bool outside_target = outside == OutsideIs::target;
  for (int axis = 0; axis < 3; ++axis) {
    const std::size_t len = static_cast<std::size_t>(frame.dims[axis]);
    const double s = frame.spacing[axis];
    transform_lines(frame, dist, axis, threads, [&] {
      return [=, d = std::vector<double>(len), v = std::vector<int>(len + 3),
              z = std::vector<double>(len + 3)](std::span<float> line) mutable {
        transform_line(line, s, outside_target, d, v, z);
      };
    });
  }
  return dist;
}

}  // namespace naris
