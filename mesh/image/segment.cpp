#include "mesh/image/segment.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>

#include "core/error.h"

namespace naris {
namespace {

struct Span {
  int j, k, x0, x1;  // inclusive run along i
};

// 3D scanline flood fill with 26-connectivity: a run of voxels is filled at once; the runs it
// touches lie in the 8 neighbouring rows (j±1, k±1) between x0−1 and x1+1. Every voxel is marked
// once, so the work is linear in the region. Returns the number of voxels filled.
template <class Inside>
std::size_t flood_fill(const ImageFrame& f, std::vector<std::uint8_t>& mark, std::uint8_t value,
                       Voxel seed, Inside&& inside, std::vector<Span>& stack) {
  const int nx = f.dims[0], ny = f.dims[1], nz = f.dims[2];
  auto at = [&](int i, int j, int k) { return f.index(i, j, k); };
  auto open = [&](int i, int j, int k) {
    return mark[at(i, j, k)] != value && inside(at(i, j, k));
  };
  std::size_t filled = 0;
  auto fill_run = [&](int i, int j, int k) {
    int x0 = i, x1 = i;
    while (x0 > 0 && open(x0 - 1, j, k)) --x0;
    while (x1 + 1 < nx && open(x1 + 1, j, k)) ++x1;
    std::fill(mark.begin() + static_cast<std::ptrdiff_t>(at(x0, j, k)),
              mark.begin() + static_cast<std::ptrdiff_t>(at(x1, j, k)) + 1, value);
    filled += static_cast<std::size_t>(x1 - x0 + 1);
    stack.push_back({j, k, x0, x1});
    return x1;
  };
  stack.clear();
  if (!open(seed[0], seed[1], seed[2])) return 0;
  fill_run(seed[0], seed[1], seed[2]);
  while (!stack.empty()) {
    const Span s = stack.back();
    stack.pop_back();
    for (int dk = -1; dk <= 1; ++dk)
      for (int dj = -1; dj <= 1; ++dj) {
        if (dj == 0 && dk == 0) continue;
        const int j = s.j + dj, k = s.k + dk;
        if (j < 0 || j >= ny || k < 0 || k >= nz) continue;
        for (int i = std::max(0, s.x0 - 1); i <= std::min(nx - 1, s.x1 + 1); ++i)
          if (open(i, j, k)) i = fill_run(i, j, k);
      }
  }
  return filled;
}

}  // namespace

double air_threshold(const Volume<float>& ct) {
  const auto [lo_it, hi_it] = std::minmax_element(ct.values.begin(), ct.values.end());
  const double lo = *lo_it, hi = *hi_it;
  if (!(hi > lo)) fail("the image is constant ({}): no threshold separates anything", lo);
  // 4 HU bins (or finer for a narrow range), smoothed over ±25 HU to remove noise minima.
  const int bins = static_cast<int>(std::clamp((hi - lo) / 4.0, 64.0, 4096.0));
  const double width = (hi - lo) / bins;
  std::vector<double> h(static_cast<std::size_t>(bins), 0.0);
  for (float v : ct.values)
    ++h[static_cast<std::size_t>(std::min(bins - 1, static_cast<int>((v - lo) / width)))];
  const int radius = std::max(1, static_cast<int>(25.0 / width));
  std::vector<double> s(h.size(), 0.0);
  for (int b = 0; b < bins; ++b) {
    double sum = 0;
    int n = 0;
    for (int d = -radius; d <= radius; ++d)
      if (b + d >= 0 && b + d < bins) sum += h[static_cast<std::size_t>(b + d)], ++n;
    s[static_cast<std::size_t>(b)] = sum / n;
  }
  // The valley next to air: the air peak is the fullest bin below −500 HU, the tissue peak the
  // fullest bin above it; the threshold is the centre of the valley floor between them. Noise
  // dips on a peak's flank are not valleys.
  double best = NAN;
  auto bin_of = [&](double hu) {
    return std::clamp(static_cast<int>((hu - lo) / width), 0, bins - 1);
  };
  const int air_end = bin_of(-500.0);
  if (lo < -500.0 && air_end > 0) {
    const int air = static_cast<int>(std::max_element(s.begin(), s.begin() + air_end) - s.begin());
    const int tissue_start = std::min(bins - 1, air + std::max(1, static_cast<int>(200.0 / width)));
    const int tissue =
        static_cast<int>(std::max_element(s.begin() + tissue_start, s.end()) - s.begin());
    if (tissue > air + 1) {
      const auto low = std::min_element(s.begin() + air, s.begin() + tissue + 1);
      const double floor = *low;
      const double peak =
          std::min(s[static_cast<std::size_t>(air)], s[static_cast<std::size_t>(tissue)]);
      if (floor < 0.5 * peak) {
        // The valley floor: the contiguous bins around the minimum within a tenth of the way up
        // to the lower peak; sparse counts make the single lowest bin arbitrary, the band is not.
        const double band = floor + 0.1 * (peak - floor);
        int b0 = static_cast<int>(low - s.begin()), b1 = b0;
        while (b0 - 1 > air && s[static_cast<std::size_t>(b0 - 1)] <= band) --b0;
        while (b1 + 1 < tissue && s[static_cast<std::size_t>(b1 + 1)] <= band) ++b1;
        best = lo + (0.5 * (b0 + b1) + 0.5) * width;
      }
    }
  }
  if (std::isnan(best))
    fail(
        "the HU histogram has no valley between air and tissue (range {:.0f} to {:.0f}); give "
        "the threshold explicitly",
        lo, hi);
  return best;
}

Voxel parse_seed(const std::string& text, const ImageFrame& frame) {
  static const std::regex form(
      R"(^\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*(mm)?\s*$)");
  std::smatch m;
  if (!std::regex_match(text, m, form))
    fail("seed '{}' not understood: give voxel indices i,j,k or millimetres x,y,z mm", text);
  const Eigen::Vector3d v(std::stod(m[1].str()), std::stod(m[2].str()), std::stod(m[3].str()));
  const Eigen::Vector3d ijk = m[4].matched ? frame.continuous_index(v) : v;
  const Voxel voxel{static_cast<int>(std::lround(ijk[0])), static_cast<int>(std::lround(ijk[1])),
                    static_cast<int>(std::lround(ijk[2]))};
  for (int a = 0; a < 3; ++a)
    if (voxel[a] < 0 || voxel[a] >= frame.dims[a])
      fail("seed '{}' lies outside the volume (voxel {},{},{} of {}×{}×{})", text, voxel[0],
           voxel[1], voxel[2], frame.dims[0], frame.dims[1], frame.dims[2]);
  return voxel;
}

namespace {
// A threshold's side: below or above (a label is not a threshold).
bool above(InsideRule side) {
  if (side == InsideRule::label) fail("internal: a threshold has no label side");
  return side == InsideRule::above;
}
}  // namespace

Volume<std::uint8_t> grow_region(const Volume<float>& image, double threshold, InsideRule side,
                                 const std::vector<Voxel>& seeds) {
  if (seeds.empty()) fail("region growing needs at least one seed");
  const bool inside_above = above(side);
  Volume<std::uint8_t> mask;
  mask.frame = image.frame;
  mask.values.assign(image.values.size(), 0);
  const auto t = static_cast<float>(threshold);
  auto inside = [&](std::size_t n) {
    return inside_above ? image.values[n] > t : image.values[n] < t;
  };
  std::vector<Span> stack;
  for (const Voxel& s : seeds) {
    const std::size_t n = image.frame.index(s[0], s[1], s[2]);
    if (!inside(n))
      fail(
          "seed at voxel {},{},{} is not inside: its value {} is {} the threshold {} (place it in "
          "the airway)",
          s[0], s[1], s[2], image.values[n], inside_above ? "not above" : "not below", threshold);
    flood_fill(image.frame, mask.values, 1, s, inside, stack);
  }
  return mask;
}

Volume<std::uint8_t> threshold_mask(const Volume<float>& image, double threshold, InsideRule side) {
  const bool inside_above = above(side);
  Volume<std::uint8_t> mask;
  mask.frame = image.frame;
  mask.values.resize(image.values.size());
  const auto t = static_cast<float>(threshold);
  for (std::size_t n = 0; n < image.values.size(); ++n)
    mask.values[n] = inside_above ? image.values[n] > t : image.values[n] < t;
  return mask;
}

ComponentSummary keep_largest_component(Volume<std::uint8_t>& mask) {
  // Pass 1 marks each component 2 while counting it; pass 2 refills the largest with 3; the
  // rest is cleared. One byte per voxel throughout.
  ComponentSummary summary;
  const ImageFrame& f = mask.frame;
  std::vector<Span> stack;
  auto is_one = [&](std::size_t n) { return mask.values[n] == 1 || mask.values[n] == 2; };
  Voxel best{0, 0, 0};
  std::size_t best_size = 0, total = 0;
  for (int k = 0; k < f.dims[2]; ++k)
    for (int j = 0; j < f.dims[1]; ++j)
      for (int i = 0; i < f.dims[0]; ++i) {
        if (mask.values[f.index(i, j, k)] != 1) continue;
        const std::size_t size = flood_fill(f, mask.values, 2, {i, j, k}, is_one, stack);
        ++summary.components;
        total += size;
        if (size > best_size) best_size = size, best = {i, j, k};
      }
  if (summary.components == 0) fail("the mask is empty: nothing to keep");
  flood_fill(
      f, mask.values, 3, best, [&](std::size_t n) { return mask.values[n] == 2; }, stack);
  for (auto& v : mask.values) v = v == 3;
  summary.kept_voxels = best_size;
  summary.dropped_voxels = total - best_size;
  return summary;
}

}  // namespace naris
