#include "mesh/image/phantom.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <thread>

#include "core/error.h"
#include "core/parallel.h"

namespace naris {

// The section parameters at one depth s (mm behind the naris). The common meatus is a vertical
// capsule at lateral offset uc from hb to ht with radius rc; branch b leaves it at a fraction of
// its height, runs `len` laterally (rising slightly) and then `drop` down along the lateral wall,
// with radius rm: the meatus under a turbinate. The olfactory slit rises `olf` above ht.
struct NasalPhantom::Keyframe {
  double s;
  double uc, hb, ht, rc;
  double olf;
  std::array<double, 3> len, drop;
  double rm;
};

namespace {

using Keyframe = NasalPhantom::Keyframe;

// Subject 1, tuned against Table 4.3 (naris 164 mm² / 46 mm; planes at 33.5 … 85 mm).
constexpr Keyframe kKeyframes[] = {
    // s     uc    hb    ht    rc    olf   len               drop              rm
    {0.0, 9.0, 8.0, 8.0, 7.22, 0.0, {0, 0, 0}, {0, 0, 0}, 1.0},
    {6.0, 8.0, 6.0, 12.0, 4.5, 0.0, {0, 0, 0}, {0, 0, 0}, 1.0},
    {14.0, 4.5, 5.0, 20.0, 1.6, 0.0, {0, 0, 0}, {0, 0, 0}, 1.0},
    {22.0, 3.5, 3.0, 30.0, 1.9, 0.0, {0, 0, 0}, {0, 0, 0}, 1.0},
    {33.5, 3.0, 2.5, 33.6, 2.2, 0.0, {0, 0, 0}, {0, 0, 0}, 1.0},
    {44.0, 3.0, 2.5, 35.0, 1.7, 3.0, {8.0, 7.0, 3.5}, {5.0, 5.0, 2.0}, 1.3},
    {54.5, 3.0, 2.5, 36.0, 1.45, 6.0, {11.0, 9.0, 5.5}, {6.0, 6.0, 4.0}, 1.35},
    {65.0, 3.0, 2.5, 36.5, 1.5, 6.0, {10.0, 8.0, 5.0}, {6.0, 5.5, 4.0}, 1.4},
    {75.5, 3.0, 2.5, 37.0, 2.0, 4.0, {8.0, 6.0, 3.0}, {5.0, 4.0, 2.0}, 1.35},
    {85.0, 3.5, 3.0, 38.2, 2.8, 0.0, {0, 0, 0}, {0, 0, 0}, 1.3},
    {96.0, 5.0, 10.0, 26.0, 6.0, 0.0, {0, 0, 0}, {0, 0, 0}, 1.3},
};
constexpr double kBranchAttach[3] = {0.2, 0.48, 0.74};  // inferior, middle, superior
constexpr double kOlfactoryRadius = 0.5;                // a 1 mm slit
constexpr double kHuAir = -1000.0, kHuSoft = 40.0, kHuBone = 700.0;
// Scan extent in the section plane (mm): u from the septum laterally, h above the floor.
constexpr double kU0 = -4.0, kU1 = 26.0, kH0 = -6.0, kH1 = 50.0;

double smoothstep(double t) {
  return t * t * (3.0 - 2.0 * t);
}

Keyframe keyframe_at(double s) {
  constexpr int n = static_cast<int>(std::size(kKeyframes));
  if (s <= kKeyframes[0].s) return kKeyframes[0];
  if (s >= kKeyframes[n - 1].s) return kKeyframes[n - 1];
  int k = 0;
  while (kKeyframes[k + 1].s < s) ++k;
  const Keyframe& a = kKeyframes[k];
  const Keyframe& b = kKeyframes[k + 1];
  // Smoothstep blending: every parameter is C¹ in s, so the walls have no creases across.
  const double t = smoothstep((s - a.s) / (b.s - a.s));
  auto mix = [t](double x, double y) { return x + (y - x) * t; };
  Keyframe r{
      s,  mix(a.uc, b.uc), mix(a.hb, b.hb), mix(a.ht, b.ht), mix(a.rc, b.rc), mix(a.olf, b.olf), {},
      {}, mix(a.rm, b.rm)};
  for (int i = 0; i < 3; ++i) {
    r.len[i] = mix(a.len[i], b.len[i]);
    r.drop[i] = mix(a.drop[i], b.drop[i]);
  }
  return r;
}

struct Capsule {
  double ax, ay, bx, by, r;
  double field(double u, double h) const {
    const double dx = bx - ax, dy = by - ay;
    const double len2 = dx * dx + dy * dy;
    double t = len2 > 0.0 ? ((u - ax) * dx + (h - ay) * dy) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return std::hypot(u - ax - t * dx, h - ay - t * dy) - r;
  }
};

// One section as capsules; the common meatus carries the septal bulge, which pushes its medial
// wall laterally by `bulge(h)` (the lateral wall stays).
struct Section {
  Capsule capsules[8];
  int count = 0;
  Capsule common;
  double bulge = 0.0, bulge_h = 0.0, bulge_sigma = 6.0;

  double field(double u, double h) const {
    double b = 0.0;
    if (bulge > 0.0) {
      const double z = (h - bulge_h) / bulge_sigma;
      b = bulge * std::exp(-z * z);
    }
    Capsule c = common;
    c.ax += 0.5 * b;
    c.bx += 0.5 * b;
    c.r = std::max(0.25, c.r - 0.5 * b);
    double f = c.field(u, h);
    for (int i = 0; i < count; ++i) f = std::min(f, capsules[i].field(u, h));
    return f;
  }
};

}  // namespace

NasalPhantom::NasalPhantom(int subject) : subject_(subject) {
  if (subject < 1) fail("phantom subject {} is not valid: subjects are numbered from 1", subject);
  if (subject > 1) {
    // Deterministic per subject, and independent of the platform's distributions.
    std::mt19937_64 rng(0x9E3779B97F4A7C15ull * static_cast<unsigned>(subject));
    auto uniform = [&rng](double lo, double hi) {
      return lo + (hi - lo) * static_cast<double>(rng() >> 11) * 0x1.0p-53;
    };
    for (double& b : variation_.branch_scale) b = uniform(0.75, 1.25);
    variation_.meatus_width_scale = uniform(0.85, 1.15);
    variation_.septal_bulge = uniform(0.2, 1.0);
  }
  if (subject == 3) variation_.obstruction = 0.3;
}

namespace {

// The section of a subject at depth s.
Section section_of(const NasalPhantom::Variation& v, double s) {
  const Keyframe k = keyframe_at(s);
  const double bulge = v.septal_bulge, obstruction = v.obstruction;
  Section sec;
  sec.common = {k.uc, k.hb, k.uc, k.ht, k.rc};
  if (bulge > 0.0) {
    const double z = (k.s - 40.0) / 10.0;
    sec.bulge = bulge * std::exp(-z * z);
    sec.bulge_h = 0.5 * (k.hb + k.ht);
  }
  if (k.olf > 0.0)
    sec.capsules[sec.count++] = {k.uc, k.ht, k.uc, k.ht + k.olf + k.rc, kOlfactoryRadius};
  double below_top = 0.0;  // the highest air of the branch below
  for (int b = 0; b < 3; ++b) {
    const double len = k.len[b] * v.branch_scale[b];
    if (len <= 0.05) continue;
    double rm = k.rm * v.meatus_width_scale;
    if (b == 1 && obstruction < 1.0) {
      // A partial obstruction of the middle meatus (like study 3), over 50 … 70 mm.
      const double w =
          std::clamp((k.s - 50.0) / 4.0, 0.0, 1.0) * std::clamp((70.0 - k.s) / 4.0, 0.0, 1.0);
      rm *= 1.0 - (1.0 - obstruction) * smoothstep(w);
    }
    // Branches grow out of the wall: their radius follows their length while they are short.
    rm = std::min(rm, 0.5 * len + 0.2);
    const double h = k.hb + kBranchAttach[b] * (k.ht - k.hb);
    const double ue = k.uc + len, he = h + 0.2 * len;
    double drop = k.drop[b] * v.branch_scale[b];
    // The meatus runs down the lateral wall but stops 2 mm of tissue short of the branch below
    // (the inferior one at the floor): a turbinate stays attached to the lateral wall, never an
    // island.
    drop = std::min(drop, he - rm - (b == 0 ? k.hb - k.rc : below_top + 2.0));
    below_top = he + rm;
    sec.capsules[sec.count++] = {k.uc, h, ue, he, rm};
    if (drop > 0.05) sec.capsules[sec.count++] = {ue, he, ue + 0.3 * drop, he - drop, rm};
  }
  return sec;
}

// Hounsfield value at (u, h) of a section at depth s (no noise, no partial volume).
double hounsfield(const Section& sec, double u, double h, double s) {
  const double f = sec.field(u, h);
  if (f < 0.0) return kHuAir;
  // A bony shell 1 … 2.2 mm from the airway (turbinate cores, lateral wall, septum) behind the
  // cartilaginous vestibule; soft tissue and mucosa elsewhere.
  const double bone_weight = smoothstep(std::clamp((s - 16.0) / 6.0, 0.0, 1.0));
  if (f >= 1.0 && f < 2.2) return kHuSoft + bone_weight * (kHuBone - kHuSoft);
  return kHuSoft;
}

}  // namespace

double NasalPhantom::section_field(double u, double h, double s) const {
  return section_of(variation_, s).field(u, h);
}

bool NasalPhantom::in_airway(const Eigen::Vector3d& x) const {
  return section_field(-x[0], x[2], x[1]) < 0.0;
}

ImageFrame NasalPhantom::frame(double pixel, double slice) const {
  if (!(pixel > 0.0) || !(slice > 0.0))
    fail("phantom pixel and slice spacing must be positive (got {} and {} mm)", pixel, slice);
  ImageFrame f;
  f.dims = {static_cast<int>(std::lround((kU1 - kU0) / pixel)) + 1,
            static_cast<int>(std::lround((kH1 - kH0) / pixel)) + 1,
            static_cast<int>(std::lround(length() / slice)) + 1};
  f.spacing = {pixel, pixel, slice};
  // i lateral (patient right, −L), j superior (+S), k posterior (+P): right-handed.
  f.direction << -1, 0, 0, 0, 0, 1, 0, 1, 0;
  f.origin = {-kU0, 0.0, kH0};
  return f;
}

Eigen::Vector3d NasalPhantom::seed_point() const {
  const Keyframe k = keyframe_at(0.0);
  return {-k.uc, 0.0, 0.5 * (k.hb + k.ht)};
}

std::array<double, 2> NasalPhantom::section_area_perimeter(double s, double step) const {
  if (!(step > 0.0)) fail("section sampling step must be positive");
  const Section sec = section_of(variation_, s);
  // Sample only the capsules' bounding box (with a margin of two steps): the rest is tissue.
  double u0 = std::min(sec.common.ax, sec.common.bx) - sec.common.r;
  double u1 = std::max(sec.common.ax, sec.common.bx) + sec.common.r;
  double h0 = std::min(sec.common.ay, sec.common.by) - sec.common.r;
  double h1 = std::max(sec.common.ay, sec.common.by) + sec.common.r;
  for (int c = 0; c < sec.count; ++c) {
    const Capsule& k = sec.capsules[c];
    u0 = std::min({u0, k.ax - k.r, k.bx - k.r});
    u1 = std::max({u1, k.ax + k.r, k.bx + k.r});
    h0 = std::min({h0, k.ay - k.r, k.by - k.r});
    h1 = std::max({h1, k.ay + k.r, k.by + k.r});
  }
  u0 -= 2 * step;
  h0 -= 2 * step;
  const int nu = static_cast<int>((u1 - u0) / step) + 5;
  const int nh = static_cast<int>((h1 - h0) / step) + 5;
  std::vector<double> row0(nu), row1(nu);
  auto fill = [&](std::vector<double>& row, int j) {
    for (int i = 0; i < nu; ++i) row[i] = sec.field(u0 + i * step, h0 + j * step);
  };
  double area = 0.0, perimeter = 0.0;
  fill(row0, 0);
  for (int j = 0; j + 1 < nh; ++j) {
    fill(row1, j + 1);
    for (int i = 0; i + 1 < nu; ++i) {
      const double f[4] = {row0[i], row0[i + 1], row1[i + 1], row1[i]};  // counter-clockwise
      int inside = 0;
      for (double v : f) inside += v < 0.0;
      area += 0.25 * inside * step * step;
      if (inside == 0 || inside == 4) continue;
      // Marching squares: crossing points on the cell edges, joined in pairs.
      const double cx[4] = {0, 1, 1, 0}, cy[4] = {0, 0, 1, 1};
      double px[4], py[4];
      int n = 0;
      for (int e = 0; e < 4; ++e) {
        const double a = f[e], b = f[(e + 1) % 4];
        if ((a < 0.0) == (b < 0.0)) continue;
        const double t = a / (a - b);
        const int e1 = (e + 1) % 4;
        px[n] = cx[e] + t * (cx[e1] - cx[e]);
        py[n] = cy[e] + t * (cy[e1] - cy[e]);
        ++n;
      }
      for (int q = 0; q + 1 < n; q += 2)
        perimeter += step * std::hypot(px[q + 1] - px[q], py[q + 1] - py[q]);
    }
    std::swap(row0, row1);
  }
  return {area, perimeter};
}

Volume<float> render_phantom_ct(const NasalPhantom& phantom, const PhantomSampling& sampling,
                                int threads) {
  if (sampling.subsamples < 1 || sampling.slice_samples < 1)
    fail("phantom sampling needs at least one sample per pixel and per slice");
  if (!(sampling.noise >= 0.0)) fail("phantom noise must be ≥ 0 HU (got {})", sampling.noise);
  Volume<float> ct;
  ct.frame = phantom.frame(sampling.pixel, sampling.slice);
  const auto [ni, nj, nk] = ct.frame.dims;
  ct.values.assign(ct.frame.voxel_count(), 0.0f);
  threads = static_cast<int>(thread_count(threads));
  const int sub = sampling.subsamples, ss = sampling.slice_samples;
  const double pixel = sampling.pixel, slice = sampling.slice;
  auto render_slice = [&](int k) {
    // Noise per slice from its own stream: the scan does not depend on the thread count.
    std::mt19937_64 rng(0xC0FFEEull * static_cast<unsigned>(phantom.subject()) + 7919ull * k);
    std::normal_distribution<double> noise(0.0, sampling.noise);
    std::vector<double> sum(static_cast<std::size_t>(ni) * nj, 0.0);
    for (int q = 0; q < ss; ++q) {
      // Rectangular slice profile: samples at the centres of ss equal parts of the thickness.
      const double s = slice * (k + (q + 0.5) / ss - 0.5);
      const Section sec = section_of(phantom.variation(), s);  // the same for the whole plane
      for (int j = 0; j < nj; ++j)
        for (int i = 0; i < ni; ++i) {
          double acc = 0.0;
          for (int b = 0; b < sub; ++b)
            for (int a = 0; a < sub; ++a) {
              const double u = kU0 + pixel * (i + (a + 0.5) / sub - 0.5);
              const double h = kH0 + pixel * (j + (b + 0.5) / sub - 0.5);
              acc += hounsfield(sec, u, h, s);
            }
          sum[static_cast<std::size_t>(j) * ni + i] += acc;
        }
    }
    const double scale = 1.0 / (static_cast<double>(sub) * sub * ss);
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i)
        ct.at(i, j, k) = static_cast<float>(sum[static_cast<std::size_t>(j) * ni + i] * scale +
                                            (sampling.noise > 0.0 ? noise(rng) : 0.0));
  };
  std::vector<std::thread> pool;
  std::atomic<int> next{0};
  for (int t = 0; t < threads; ++t)
    pool.emplace_back([&] {
      for (int k; (k = next++) < nk;) render_slice(k);
    });
  for (auto& t : pool) t.join();
  return ct;
}

Volume<std::uint8_t> phantom_mask(const NasalPhantom& phantom, const ImageFrame& grid) {
  Volume<std::uint8_t> mask;
  mask.frame = grid;
  mask.values.assign(grid.voxel_count(), 0);
  const auto [ni, nj, nk] = grid.dims;
  // Sections depend on the depth alone: reuse one while the depth stays (a whole coronal slice).
  double cached_s = std::numeric_limits<double>::quiet_NaN();
  Section section;
  for (int k = 0; k < nk; ++k)
    for (int j = 0; j < nj; ++j)
      for (int i = 0; i < ni; ++i) {
        const Eigen::Vector3d x = grid.physical(Eigen::Vector3d(i, j, k));
        if (x[1] != cached_s) {
          cached_s = x[1];
          section = section_of(phantom.variation(), x[1]);
        }
        mask.at(i, j, k) = section.field(-x[0], x[2]) < 0.0 ? 1 : 0;
      }
  return mask;
}

double dice(const Volume<std::uint8_t>& a, const Volume<std::uint8_t>& b) {
  if (a.frame.dims != b.frame.dims) fail("Dice needs two masks on the same grid");
  std::size_t na = 0, nb = 0, both = 0;
  for (std::size_t n = 0; n < a.values.size(); ++n) {
    const bool x = a.values[n] != 0, y = b.values[n] != 0;
    na += x;
    nb += y;
    both += x && y;
  }
  return na + nb == 0 ? 1.0 : 2.0 * static_cast<double>(both) / static_cast<double>(na + nb);
}

}  // namespace naris
