// Leave-slices-out on the real airway (Grevera & Udupa 1998): from ../shared/data/neonate-a.nrrd
// keep every third slice along the thick axis (axis 0, 0.75 mm), rebuild the two removed slices
// between each kept pair with each method, and compare with the originals: Dice over the
// removed slices and the symmetric surface distance (mean, in-plane, mm).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/log.h"
#include "mesh/image/interpolate_slices.h"
#include "mesh/image/read_volume.h"

using namespace naris;

namespace {

struct Score {
  double dice = 0, surface_mm = 0;
};

std::vector<std::pair<int, int>> boundary(const Image2D& m) {
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      if (m.at(x, y) < 0.5) continue;
      bool edge = false;
      for (auto [dx, dy] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int xx = x + dx, yy = y + dy;
        edge = edge || xx < 0 || yy < 0 || xx >= m.width || yy >= m.height || m.at(xx, yy) < 0.5;
      }
      if (edge) out.push_back({x, y});
    }
  return out;
}

// Mean distance from each boundary pixel of one mask to the other's boundary, both ways.
double surface_distance(const Image2D& a, const Image2D& b, double sx, double sy, std::size_t& n) {
  const auto ba = boundary(a), bb = boundary(b);
  if (ba.empty() || bb.empty()) return 0.0;
  double sum = 0.0;
  auto one_way = [&](const auto& from, const auto& to) {
    for (auto [x, y] : from) {
      double best = INFINITY;
      for (auto [u, v] : to) best = std::min(best, std::hypot((x - u) * sx, (y - v) * sy));
      sum += best;
      ++n;
    }
  };
  one_way(ba, bb);
  one_way(bb, ba);
  return sum;
}

}  // namespace

int main() {
  const std::filesystem::path data = std::filesystem::path(NARIS_SHARED_DATA) / "neonate-a.nrrd";
  if (!std::filesystem::exists(data)) {
    std::printf("skipping: %s is absent\n", data.c_str());
    return 0;
  }
  const Volume<float> full = read_volume(data);
  const int axis = 0, n = full.dims()[axis];
  Volume<float> kept;
  kept.frame = full.frame;
  kept.frame.dims[axis] = (n - 1) / 3 + 1;
  kept.frame.spacing[axis] *= 3;
  kept.values.resize(kept.frame.voxel_count());
  for (int s = 0; s < kept.frame.dims[axis]; ++s)
    set_slice_across(kept, axis, s, slice_across(full, axis, 3 * s));
  std::printf("neonate-a: %d slices of %d×%d along axis 0 (%.2f mm); kept %d, rebuilding %d\n\n", n,
              full.dims()[1], full.dims()[2], full.frame.spacing[0], kept.frame.dims[axis],
              2 * (kept.frame.dims[axis] - 1));
  std::printf("%-8s %8s %10s %22s\n", "method", "time s", "Dice", "surface distance (mm)");
  HsrOptions hsr;
  hsr.block = 8;
  hsr.levels = 4;
  hsr.iterations = 30;
  for (const char* name : {"hsr", "linear", "shape"}) {
    Stopwatch clock;
    const Volume<float> rebuilt = interpolate_slices(kept, axis, 2, parse_slice_method(name), hsr);
    const double seconds = clock.seconds();
    std::size_t inter = 0, sum = 0, count = 0;
    double surface = 0.0;
    for (int s = 0; s < rebuilt.dims()[axis] && s < n; ++s) {
      if (s % 3 == 0) continue;
      const Image2D a = slice_across(rebuilt, axis, s), b = slice_across(full, axis, s);
      for (std::size_t k = 0; k < a.v.size(); ++k) {
        inter += a.v[k] > 0.5 && b.v[k] > 0.5;
        sum += (a.v[k] > 0.5) + (b.v[k] > 0.5);
      }
      surface += surface_distance(a, b, full.frame.spacing[1], full.frame.spacing[2], count);
    }
    std::printf("%-8s %8.2f %10.4f %22.4f\n", name, seconds, 2.0 * inter / sum, surface / count);
  }
  return 0;
}
