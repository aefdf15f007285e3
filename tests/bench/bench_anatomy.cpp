// The nasal airway of the NasalSeg head CTs (Data: NasalSeg (Zhang et al., 2024), CC BY 4.0)
// against their expert labels, on each scan's own grid: Dice, volume ratio and the mean
// symmetric surface distance for the right cavity (label 3) and for both cavities with the
// nasopharynx (labels 3, 4, 5), with the time of each segmentation; then each case's stages
// from the CT to the mesh as `naris run cases/nasalseg-*` takes them, timed.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/log.h"
#include "mesh/image/distance_transform.h"
#include "mesh/image/image_jobs.h"
#include "mesh/image/nasal_airway.h"
#include "mesh/image/read_volume.h"
#include "mesh/pipeline/mesh_job.h"
#include "postproc/figures/canvas.h"
#include "tests/mesh/image/expert_labels.h"

using namespace naris;
namespace fs = std::filesystem;

namespace {

std::vector<std::uint8_t> surface(const ImageFrame& f, const std::vector<std::uint8_t>& m) {
  std::vector<std::uint8_t> s(m.size(), 0);
  for (int k = 0; k < f.dims[2]; ++k)
    for (int j = 0; j < f.dims[1]; ++j)
      for (int i = 0; i < f.dims[0]; ++i) {
        const std::size_t q = f.index(i, j, k);
        if (!m[q]) continue;
        const int c[3] = {i, j, k};
        for (int a = 0; a < 3; ++a)
          for (int d : {-1, 1}) {
            int x[3] = {c[0], c[1], c[2]};
            x[a] += d;
            if (x[a] < 0 || x[a] >= f.dims[a] || !m[f.index(x[0], x[1], x[2])]) s[q] = 1;
          }
      }
  return s;
}

struct Score {
  double dice, ratio, surface_mm;
};

Score score(const ImageFrame& f, const std::vector<std::uint8_t>& a, const Volume<float>& labels,
            std::initializer_list<int> wanted) {
  const std::vector<std::uint8_t> b = testing::label_mask(labels, wanted);
  const testing::Overlap o = testing::overlap(a, b);
  const auto sa = surface(f, a), sb = surface(f, b);
  const auto da = squared_distance(f, sa), db = squared_distance(f, sb);
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t q = 0; q < a.size(); ++q) {
    if (sa[q]) sum += std::sqrt(db[q]), ++count;
    if (sb[q]) sum += std::sqrt(da[q]), ++count;
  }
  return {o.dice, o.volume_ratio, sum / static_cast<double>(count)};
}

// Coronal slices of the CT with the naris mask and the expert's label over it: blue both, red
// naris only, green the expert only (docs/results/anatomy.md).
void draw_slices(const Volume<float>& ct, const std::vector<std::uint8_t>& mask,
                 const Volume<float>& labels, float label, std::initializer_list<int> slices,
                 const std::string& title, const fs::path& path) {
  const auto& d = ct.frame.dims;
  const double px = 4.0, pz = px * ct.frame.spacing[2] / ct.frame.spacing[0], gap = 16.0;
  const double panel = d[0] * px, height = d[2] * pz;
  figures::Canvas canvas(static_cast<int>(slices.size() * (panel + gap) + gap),
                         static_cast<int>(height + 110));
  cairo_t* cr = canvas.cr();
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);  // voxels edge to edge, no seams
  double x0 = gap;
  for (int j : slices) {
    for (int k = 0; k < d[2]; ++k)
      for (int i = 0; i < d[0]; ++i) {
        const std::size_t q = ct.frame.index(i, j, k);
        const double g = std::clamp((ct.values[q] + 1000.0) / 1400.0, 0.0, 1.0);
        const bool m = mask[q], l = labels.values[q] == label;
        double c[3] = {g, g, g};
        const double tint[3][3] = {{0.24, 0.51, 0.9}, {0.9, 0.16, 0.16}, {0.16, 0.78, 0.24}};
        if (m || l) {
          const double* t = tint[m && l ? 0 : m ? 1 : 2];
          for (int a = 0; a < 3; ++a) c[a] = (g + 2.0 * t[a]) / 3.0;
        }
        cairo_set_source_rgb(cr, c[0], c[1], c[2]);
        // The patient's right on the left of the page, superior up.
        cairo_rectangle(cr, x0 + i * px, 40 + (d[2] - 1 - k) * pz, px, pz);
        cairo_fill(cr);
      }
    cairo_set_source_rgb(cr, 0, 0, 0);
    canvas.text(x0 + 0.5 * panel, 30, fmt::format("j = {}", j), 14, 0.5, 1.0);
    x0 += panel + gap;
  }
  cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
  cairo_set_source_rgb(cr, 0, 0, 0);
  canvas.text(gap, height + 60, title, 13, 0.0, 0.5);
  canvas.text(gap, height + 82,
              "Blue: both; red: naris only; green: the expert only. Data: NasalSeg (Zhang et al., "
              "2024), CC BY 4.0.",
              12, 0.0, 0.5);
  canvas.write_png(path);
}

// The case's stages on one scan (HSR to isotropic slices, the right cavity, the mesh between its
// naris and choana), in a scratch folder; prints a table row.
void case_stages(const char* name, const fs::path& ct_file, const fs::path& scratch) {
  fs::create_directories(scratch);
  const InterpolateJob interpolate{.input = ct_file, .output = scratch / "interpolated.nrrd"};
  const InterpolateJobResult i = run_interpolate_job(interpolate);
  SegmentJob segment;
  segment.input = interpolate.output;
  segment.output = scratch / "airway.nrrd";
  segment.airway = "nasal";
  const SegmentJobResult s = run_segment_job(segment);
  MeshJob mesh;
  mesh.input = segment.output;
  mesh.label.emplace(1, '1');  // the airway's label
  mesh.inlet = s.nasal->inlet;
  mesh.outlet = s.nasal->outlet;
  mesh.relocate = true;
  mesh.output = scratch / "mesh.h5";
  Stopwatch clock;
  MeshJobResult m = run_mesh_job(mesh);
  write_mesh_outputs(mesh, m);
  const double t_mesh = clock.seconds();
  std::printf("| %s | %.2f | %.2f | %.2f | %zu k | %.2f |\n", name, i.seconds, s.seconds, t_mesh,
              m.mesh.cell_count() / 1000, i.seconds + s.seconds + t_mesh);
}

}  // namespace

int main(int argc, char** argv) {
  // --figure PATH: also draw P005's right cavity on two coronal slices.
  fs::path figure;
  if (argc > 2 && std::string(argv[1]) == "--figure") figure = argv[2], argc -= 2, argv += 2;
  const fs::path dir = argc > 1 ? fs::path(argv[1]) : fs::path(NARIS_SHARED_DATA) / "nasalseg";
  if (!fs::exists(dir)) {
    std::printf("skipping: %s is absent\n", dir.c_str());
    return 0;
  }
  std::printf("Data: NasalSeg (Zhang et al., 2024), CC BY 4.0; the scan's own grid\n\n");
  std::printf(
      "| case | threshold (HU) | right: Dice | volume ratio | surface distance (mm) | "
      "time (s) | both + nasopharynx: Dice | volume ratio | surface distance (mm) | "
      "time (s) | sinuses left out (mL) | choana (slice, expert) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const char* name : {"P005", "P045", "P055"}) {
    const Volume<float> ct = read_volume(dir / (std::string(name) + "_img.nrrd"));
    const Volume<float> labels = read_volume(dir / (std::string(name) + "_seg.nrrd"));
    const int expert_choana = testing::last_slice_j(labels, 3.0f);
    Stopwatch clock;
    const NasalAirway right = segment_nasal_airway(ct, NasalAirwayOptions{});
    const double t_right = clock.seconds();
    clock = Stopwatch();
    const NasalAirway both = segment_nasal_airway(
        ct, NasalAirwayOptions{.side = NasalSide::both, .keep_nasopharynx = true});
    const double t_both = clock.seconds();
    const Score r = score(ct.frame, right.mask.values, labels, {3});
    const Score b = score(ct.frame, both.mask.values, labels, {3, 4, 5});
    if (!figure.empty() && std::string(name) == "P005")
      draw_slices(ct, right.mask.values, labels, 3.0f, {70, 100},
                  "NasalSeg P005, the right nasal cavity: naris segment --airway nasal against "
                  "the expert's label 3",
                  figure);
    std::printf(
        "| %s | %.0f | %.3f | %.2f | %.2f | %.2f | %.3f | %.2f | %.2f | %.2f | %.1f | %d, %d |\n",
        name, right.threshold, r.dice, r.ratio, r.surface_mm, t_right, b.dice, b.ratio,
        b.surface_mm, t_both, both.sinus_ml, right.choana ? *right.choana : -1, expert_choana);
  }
  std::printf(
      "\nThe case's stages (naris run cases/nasalseg-*: HSR to isotropic slices, the right "
      "cavity, the mesh relocated, with its files)\n\n");
  std::printf("| case | interpolate (s) | segment (s) | mesh (s) | cells | total (s) |\n");
  std::printf("|---|---|---|---|---|---|\n");
  const fs::path scratch = fs::temp_directory_path() / "naris-bench-anatomy";
  for (const char* name : {"P005", "P045", "P055"})
    case_stages(name, dir / (std::string(name) + "_img.nrrd"), scratch / name);
  fs::remove_all(scratch);
  std::printf("\npeak memory %.0f MB\n", static_cast<double>(peak_memory_bytes()) / 1e6);
  return 0;
}
