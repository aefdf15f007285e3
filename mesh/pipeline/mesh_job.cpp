#include "mesh/pipeline/mesh_job.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"
#include "core/log.h"
#include "core/text.h"
#include "core/units.h"
#include "mesh/image/image_jobs.h"
#include "mesh/image/smooth_label.h"
#include "mesh/io/mesh_h5.h"
#include "mesh/io/write_gmsh.h"
#include "mesh/io/write_vtk.h"
#include "mesh/patches/outlet_extension.h"
#include "mesh/refine/subdivide.h"

namespace naris {
namespace fs = std::filesystem;

namespace {

// The labels present in an image (integer values), each with its segment name where the file
// names it: "0, 3 (right half), 5 (left half)".
std::string labels_present(const Volume<float>& volume, const VolumeInfo& info) {
  std::set<int> present;
  for (float v : volume.values)
    if (v == std::floor(v) && std::abs(v) < 1e6f) present.insert(static_cast<int>(v));
  std::string list;
  for (int l : present) {
    const auto it = info.label_names.find(l);
    list += fmt::format("{}{}{}", list.empty() ? "" : ", ", l,
                        it == info.label_names.end() ? "" : " (" + it->second + ")");
  }
  return list;
}

// The labels of "3,5" or of segment names, each checked against what the image holds.
std::vector<int> parse_labels(const std::string& text, const Volume<float>& volume,
                              const MeshJob& job, const VolumeInfo& info) {
  std::vector<int> labels;
  for (std::string token : split_list(text)) {
    token.erase(0, token.find_first_not_of(' '));
    token.erase(token.find_last_not_of(' ') + 1);
    if (token.empty()) fail("label '{}': an empty item (give L or L1,L2,…)", text);
    int label = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), label);
    if (ec != std::errc() || end != token.data() + token.size()) {
      const auto it = std::find_if(info.label_names.begin(), info.label_names.end(),
                                   [&](const auto& kv) { return kv.second == token; });
      if (it == info.label_names.end())
        fail("{}: no label '{}' (labels present: {})", job.input.string(), token,
             labels_present(volume, info));
      label = it->first;
    }
    if (std::none_of(volume.values.begin(), volume.values.end(),
                     [&](float v) { return v == static_cast<float>(label); }))
      fail("{}: empty segmentation: no voxel has label {} (labels present: {})", job.input.string(),
           label, labels_present(volume, info));
    labels.push_back(label);
  }
  return labels;
}

// Decides what "inside" means and checks that it selects something but not everything. A union
// of labels turns the image into its 0/1 mask.
mve::VolumeField make_field(Volume<float>& volume, const MeshJob& job, MeshJobResult& r) {
  const auto& info = r.input;
  InsideRule mode;
  double level;
  if (job.threshold && job.label) fail("give either --threshold or --label, not both");
  if (job.label) {
    mode = InsideRule::label;
    r.labels = parse_labels(*job.label, volume, job, info);
    level = r.labels.front();
    if (r.labels.size() > 1) {
      const std::set<int> set(r.labels.begin(), r.labels.end());
      for (float& v : volume.values)
        v = v == std::floor(v) && set.count(static_cast<int>(v)) ? 1.0f : 0.0f;
      level = 1.0;
    }
  } else if (job.threshold) {
    level = *job.threshold;
    if (!(level > info.min_value && level < info.max_value))
      fail("{}: threshold {} is outside the data range [{}, {}]: nothing would be separated",
           job.input.string(), level, info.min_value, info.max_value);
    if (job.inside == InsideRule::label) fail("with a threshold, inside is below or above it");
    mode = job.inside;
  } else {
    // A binary labelmap (0/1) needs no option: its airway is label 1.
    const bool binary = info.min_value >= 0.0 && info.max_value <= 1.0 &&
                        std::all_of(volume.values.begin(), volume.values.end(),
                                    [](float v) { return v == 0.0f || v == 1.0f; });
    if (!binary)
      fail(
          "{}: the image is not a binary labelmap (values {} .. {}): give --threshold T (CT, "
          "inside below T) or --label L",
          job.input.string(), info.min_value, info.max_value);
    mode = InsideRule::label;
    level = 1.0;
  }
  std::size_t inside = 0;
  for (float v : volume.values) inside += is_inside(mode, v, level);
  if (inside == 0) {
    if (mode == InsideRule::label)
      fail("{}: empty segmentation: no voxel has label {} (labels present: {})", job.input.string(),
           level, labels_present(volume, info));
    fail("{}: no voxel is {} the threshold {}: nothing to mesh", job.input.string(),
         inside_rule_name(mode), level);
  }
  if (inside == volume.values.size())
    fail(
        "{}: every voxel is inside ({} {}): the object has no boundary in the image; check the "
        "threshold side (--inside) or crop with --inlet/--outlet",
        job.input.string(), mode == InsideRule::label ? "label" : "threshold", level);
  r.level = level;
  r.rule = mode;
  if (job.smooth > 0.0) {
    if (mode != InsideRule::label)
      fail("--smooth is for labelmaps: a CT or a scalar field has its own smooth level");
    Volume<std::uint8_t> mask;
    mask.frame = volume.frame;
    mask.values.resize(volume.values.size());
    for (std::size_t q = 0; q < volume.values.size(); ++q)
      mask.values[q] = is_inside(mode, volume.values[q], level);
    volume = smooth_label_field(mask, {.sigma = job.smooth, .threads = job.threads});
    return mve::VolumeField(volume, InsideRule::above, 0.0);
  }
  return mve::VolumeField(volume, mode, level);
}

Json quality_json(const QualityReport& q) {
  Json out = Json::object();
  for (std::size_t g = 0; g < q.groups.size(); ++g) {
    Json group = Json::object();
    for (std::size_t m = 0; m < kMetrics.size(); ++m) {
      const auto& st = q.summary[g][m];
      const std::pair<const char*, double> order_statistics[] = {
          {"min", st.min}, {"p1", st.p1},   {"p5", st.p5},  {"p50", st.p50},
          {"p95", st.p95}, {"p99", st.p99}, {"max", st.max}};
      Json stats = {{"count", st.count}};
      for (const auto& [key, value] : order_statistics) stats[key] = significant(value);
      stats["histogram_range"] = {st.lo, st.hi};
      stats["histogram"] = st.histogram;
      group[metric_name(kMetrics[m])] = std::move(stats);
    }
    out[q.groups[g]] = std::move(group);
  }
  return out;
}

// "auto": the plane the segmentation found (naris segment --airway nasal), from its sidecar,
// read once for both planes.
std::string cut_plane_text(const std::string& text, const std::string& name, const fs::path& input,
                           std::optional<Json>& sidecar) {
  if (text != "auto") return text;
  const fs::path path = segmentation_sidecar(input);
  if (!sidecar) {
    if (!fs::is_regular_file(path))
      fail("{} 'auto' takes the plane from {}, which is absent (segment with --airway nasal)", name,
           path.string());
    sidecar = read_json_file(path);
  }
  if (!sidecar->contains(name) || !(*sidecar)[name].is_string())
    fail("{} has no {} plane: give one explicitly", path.string(), name);
  return (*sidecar)[name].get<std::string>();
}

}  // namespace

MeshJobResult run_mesh_job(const MeshJob& job) {
  MeshJobResult r;
  Stopwatch total;
  // Each level multiplies the cells by 8: three turn a 10⁶-cell mesh into 5·10⁸.
  if (job.relocate && !job.improve)
    fail("relocate follows the improvement's collapses: drop --no-improve (improve: false)");
  if (job.subdivisions < 0 || job.subdivisions > 3)
    fail("subdivide is {}: give 0 to 3 levels (each multiplies the cells by 8)", job.subdivisions);
  ensure_writable_folder(job.output.parent_path());
  std::vector<Cut> cuts;
  std::optional<Json> sidecar;
  for (const auto& [name, text] : {std::pair{"inlet", job.inlet}, std::pair{"outlet", job.outlet}})
    if (text)
      cuts.push_back({name, parse_cut_plane(cut_plane_text(*text, name, job.input, sidecar))});
  std::vector<Region> regions;
  for (const auto& text : job.regions) regions.push_back(parse_region(text));

  Stopwatch clock;
  Volume<float> volume = read_volume(job.input, &r.input);
  r.seconds.push_back({"read", clock.seconds()});

  clock = Stopwatch();
  const mve::VolumeField field = make_field(volume, job, r);
  const mve::MveOptions initial{.keep_largest_component = job.keep_largest};
  mve::MveOptions options = initial;
  PreparedCuts prepared = prepare_cuts(field, cuts, options);
  std::optional<OutletExtension> extended;
  if (job.outlet_extension > 0.0) {
    extended.emplace(field, cuts, options, job.outlet_extension);
    cuts = extended->cuts();
    options = initial;
    prepared = prepare_cuts(*extended, cuts, options);
    r.extension = {
        .axis = extended->axis(), .voxels = extended->voxels(), .length_mm = extended->length_mm()};
  }
  const mve::FieldSource& source =
      extended ? static_cast<const mve::FieldSource&>(*extended) : field;
  r.mesh = mve::march_volume_elements(source, options, &r.mve);
  finish_patches(r.mesh, source, cuts, prepared, regions, options.wall_patch);
  r.seconds.push_back({"mve", clock.seconds()});

  // The quality measured before and after improvement counts as one stage, improvement as another.
  clock = Stopwatch();
  r.quality = cell_quality(r.mesh, job.threads);
  r.before = summarize_quality(r.mesh, r.quality, 20, job.threads);
  double quality_seconds = clock.seconds();
  if (job.improve) {
    clock = Stopwatch();
    std::vector<std::int64_t> unchanged_from;
    r.improvement =
        improve_mesh(r.mesh, volume.frame.spacing.minCoeff(), job.improve_options, &unchanged_from);
    // Wall nodes slide on the field's level zero; the cut planes and the box sides are flat
    // patches, whose nodes relocation keeps in their planes.
    if (job.relocate) {
      std::vector<bool> on_surface(r.mesh.patch_names.size(), true);
      for (std::size_t p = 0; p < on_surface.size(); ++p) {
        const std::string& name = r.mesh.patch_names[p];
        on_surface[p] =
            std::none_of(cuts.begin(), cuts.end(), [&](const Cut& c) { return c.patch == name; }) &&
            std::find(options.side_patch.begin(), options.side_patch.end(), name) ==
                options.side_patch.end();
      }
      r.relocation =
          relocate_nodes(r.mesh, &field, on_surface, job.relocate_options, &unchanged_from);
    }
    r.seconds.push_back({"improve", clock.seconds()});
    clock = Stopwatch();
    r.quality = cell_quality(r.mesh, r.quality, unchanged_from, job.threads);
    quality_seconds += clock.seconds();
  }
  clock = Stopwatch();
  if (job.subdivisions > 0) {
    r.cells_before_subdivision = r.mesh.cell_count();
    for (int level = 0; level < job.subdivisions; ++level) r.mesh = subdivide(r.mesh);
    r.quality = cell_quality(r.mesh, job.threads);
  }
  if (job.improve || job.subdivisions > 0) {
    r.after = summarize_quality(r.mesh, r.quality, 20, job.threads);
  } else {
    r.after = r.before;
  }
  r.seconds.push_back({"quality", quality_seconds + clock.seconds()});
  r.patches = patch_report(r.mesh);
  r.volume = mesh_volume(r.mesh);
  if (job.check) {
    clock = Stopwatch();
    r.check = check_mesh(r.mesh, job.threads);
    r.seconds.push_back({"check", clock.seconds()});
    if (!r.check->valid())
      fail(
          "internal error: the mesh of {} failed its own checks ({}); please report it with "
          "the input",
          job.input.string(), r.check->describe());
  }
  r.seconds.push_back({"total", total.seconds()});
  return r;
}

void write_mesh_outputs(const MeshJob& job, MeshJobResult& r) {
  Stopwatch clock;
  const fs::path dir = job.output.parent_path();
  auto sibling = [&](const char* name) { return dir / name; };
  write_mesh_h5(r.mesh, job.output);
  r.written.push_back(job.output.string());
  r.written.push_back(fs::path(job.output).replace_extension(".xdmf").string());
  if (job.write_vtu) {
    CellFields fields;
    for (Metric m : kMetrics) {
      auto& v = fields[metric_name(m)].values;
      v.reserve(r.quality.size());
      for (const auto& c : r.quality) v.push_back(c.get(m));
    }
    write_vtu(r.mesh, sibling("mesh.vtu"), fields);
    write_boundary_vtp(r.mesh, sibling("boundary.vtp"));
    r.written.push_back(sibling("mesh.vtu").string());
    r.written.push_back(sibling("boundary.vtp").string());
  }
  if (job.write_stl) {
    write_stl(r.mesh, sibling("surface.stl"));
    r.written.push_back(sibling("surface.stl").string());
  }
  if (job.write_msh) {
    write_gmsh22(r.mesh, sibling("mesh.msh"));
    r.written.push_back(sibling("mesh.msh").string());
  }
  r.seconds.push_back({"write", clock.seconds()});

  // mesh.json: every number of the summary, for people and for the later stages.
  Json patches = Json::array(), seconds = Json::object();
  for (const auto& p : r.patches)
    patches.push_back({{"name", p.name},
                       {"faces", p.faces},
                       {"area_mm2", significant(p.area)},
                       {"perimeter_mm", significant(p.perimeter)},
                       {"hydraulic_diameter_mm", significant(p.hydraulic_diameter())}});
  for (const auto& [stage, t] : r.seconds) seconds[stage] = significant(t, 5);
  const ImproveStats& im = r.improvement;
  Json json = {{"input", job.input.string()},
               {"mode", inside_rule_name(r.rule)},
               {"level", r.level},
               {"nodes", r.mesh.nodes.size()},
               {"cells",
                {{"tet", r.mesh.tets.size()},
                 {"pyramid", r.mesh.pyramids.size()},
                 {"hex", r.mesh.hexes.size()}}},
               {"boundary_faces",
                {{"tri", r.mesh.boundary_tris.size()}, {"quad", r.mesh.boundary_quads.size()}}},
               {"volume_mm3", significant(r.volume)},
               {"components", r.mve.components},
               {"dropped_components", r.mve.dropped_components},
               {"dropped_cells", r.mve.dropped_cells},
               {"improvement",
                {{"short_edges", im.short_edges},
                 {"collapsed", im.collapsed},
                 {"refused_topology", im.refused_topology},
                 {"refused_geometry", im.refused_geometry},
                 {"removed_cells", im.removed_cells},
                 {"pyramids_to_tets", im.pyramids_to_tets},
                 {"pyramids_split", im.pyramids_split},
                 {"vertices_warped", im.vertices_warped}}},
               {"patches", patches},
               {"outlet_extension_mm", significant(r.extension.length_mm)},
               {"quality_before", quality_json(r.before)},
               {"quality_after", quality_json(r.after)},
               {"seconds", seconds},
               {"peak_memory_mb", significant(megabytes(peak_memory_bytes()), 5)}};
  if (job.relocate)
    json["relocation"] = {
        {"cells_below_target_before", r.relocation.cells_below_before},
        {"cells_below_target_after", r.relocation.cells_below_after},
        {"worst_score_before", significant(r.relocation.worst_before)},
        {"worst_score_after", significant(r.relocation.worst_after)},
        {"nodes_moved", r.relocation.nodes_moved},
        {"moves", r.relocation.moves},
        {"rim_slides", r.relocation.rim_slides},
        {"slivers_removed", r.relocation.slivers_removed},
        {"edges_removed", r.relocation.edges_removed},
        {"largest_surface_offset_mm", significant(r.relocation.largest_surface_offset)},
        {"seconds", significant(r.relocation.seconds, 5)}};
  write_json_file(sibling("mesh.json"), json);
  r.written.push_back(sibling("mesh.json").string());
}

std::string format_mesh_summary(const MeshJob& job, const MeshJobResult& r) {
  const auto& m = r.mesh;
  std::string s = fmt::format(
      "naris mesh: {} ({}, {})\n  cells     {} = {} hex + {} pyramid + {} tet\n"
      "  nodes     {}\n  volume    {:.1f} mm³ ({:.3f} mL)\n",
      job.input.filename().string(), r.input.format,
      r.labels.size() > 1 ? fmt::format("labels {}", fmt::join(r.labels, " + "))
      : r.rule == InsideRule::label
          ? fmt::format("label {}", r.level)
          : fmt::format("inside {} {}", inside_rule_name(r.rule), r.level),
      m.cell_count(), m.hexes.size(), m.pyramids.size(), m.tets.size(), m.nodes.size(), r.volume,
      r.volume / 1000.0);
  if (r.mve.dropped_components)
    s += fmt::format("  dropped   {} small component(s), {} cells (kept the largest)\n",
                     r.mve.dropped_components, r.mve.dropped_cells);
  for (const auto& p : r.patches) {
    s += fmt::format("  patch     {:<10} {:>8} faces {:>12.2f} mm²", p.name, p.faces, p.area);
    if (p.name == "inlet" || p.name == "outlet")
      s += fmt::format("  perimeter {:.2f} mm  D_h = 4A/P = {:.3f} mm", p.perimeter,
                       p.hydraulic_diameter());
    s += "\n";
  }
  if (r.extension.axis >= 0) {
    const auto outlet = std::find_if(r.patches.begin(), r.patches.end(),
                                     [](const PatchReport& p) { return p.name == "outlet"; });
    s += fmt::format(
        "  extended  the outlet by {:.2f} mm ({} voxels along {}{})\n", r.extension.length_mm,
        r.extension.voxels, static_cast<char>('i' + r.extension.axis),
        outlet == r.patches.end() || outlet->hydraulic_diameter() <= 0.0
            ? std::string()
            : fmt::format(", {:.1f} D_h", r.extension.length_mm / outlet->hydraulic_diameter()));
  }
  auto line = [&](const char* label, const QualityReport& q) {
    const auto& all = q.summary[3];
    return fmt::format(
        "  {:<9} edge ratio p50 {:.2f} p99 {:.2f} max {:.3g} | skew p99 {:.2f} max {:.2f} | "
        "min dihedral {:.2f}° | scaled Jacobian min {:.3f}\n",
        label, all[0].p50, all[0].p99, all[0].max, all[1].p99, all[1].max, all[2].min, all[3].min);
  };
  s += line("quality", r.before);
  if (job.improve)
    s += fmt::format(
        "  improved  {} short edges collapsed ({} refused), {} cells removed, {} "
        "pyramids → tets, {} split, {} lattice vertices warped onto the boundary\n",
        r.improvement.collapsed, r.improvement.refused_topology + r.improvement.refused_geometry,
        r.improvement.removed_cells, r.improvement.pyramids_to_tets, r.improvement.pyramids_split,
        r.improvement.vertices_warped);
  if (job.relocate)
    s += fmt::format(
        "  relocated {} nodes, removed {} edges and {} wall slivers: cells below target {} → {}, "
        "worst score {:.3f} → {:.3f}\n",
        r.relocation.nodes_moved, r.relocation.edges_removed, r.relocation.slivers_removed,
        r.relocation.cells_below_before, r.relocation.cells_below_after, r.relocation.worst_before,
        r.relocation.worst_after);
  if (job.subdivisions > 0)
    s += fmt::format("  subdivided {}× (same geometry): {} → {} cells\n", job.subdivisions,
                     r.cells_before_subdivision, m.cell_count());
  if (job.improve || job.subdivisions > 0) s += line("after", r.after);
  if (r.check)
    s += fmt::format("  checked   conforming, watertight, all volumes > 0 (min {:.3g} mm³)\n",
                     r.check->min_volume);
  std::string times;
  for (const auto& [stage, sec] : r.seconds) times += fmt::format(" {} {:.2f}s", stage, sec);
  s += fmt::format("  time     {}\n  memory    peak {:.0f} MB\n", times,
                   static_cast<double>(peak_memory_bytes()) / 1e6);
  if (!r.written.empty())
    s += fmt::format("  wrote     {}\n", fmt::join(r.written, "\n            "));
  return s;
}

}  // namespace naris
