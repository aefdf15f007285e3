#include "mesh/image/image_jobs.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json.h"
#include "core/log.h"
#include "mesh/image/read_volume.h"
#include "mesh/image/resample.h"
#include "mesh/image/write_volume.h"

namespace naris {
namespace fs = std::filesystem;

namespace {

std::string dims_text(const ImageFrame& f) {
  return fmt::format("{}×{}×{}", f.dims[0], f.dims[1], f.dims[2]);
}
std::string spacing_text(const ImageFrame& f) {
  return fmt::format("{:g}×{:g}×{:g} mm", f.spacing[0], f.spacing[1], f.spacing[2]);
}

}  // namespace

PhantomJobResult run_phantom_job(const PhantomJob& job) {
  ensure_writable_folder(fs::absolute(job.output).parent_path());
  if (!job.exact_mask.empty()) ensure_writable_folder(fs::absolute(job.exact_mask).parent_path());
  if (!(job.mask_spacing > 0.0))
    fail("phantom mask spacing must be positive (got {} mm)", job.mask_spacing);
  Stopwatch clock;
  const NasalPhantom phantom(job.subject);
  PhantomJobResult r;
  const Volume<float> ct = render_phantom_ct(phantom, job.sampling);
  r.ct = ct.frame;
  write_ct_nrrd(ct, job.output);
  if (!job.exact_mask.empty()) {
    ImageFrame grid = ct.frame;
    grid.dims[2] = static_cast<int>(std::lround(phantom.length() / job.mask_spacing)) + 1;
    grid.spacing[2] = job.mask_spacing;
    const Volume<std::uint8_t> mask = phantom_mask(phantom, grid);
    r.mask = grid;
    write_labelmap_nrrd(mask, job.exact_mask);
  }
  r.seed = phantom.seed_point();
  r.seconds = clock.seconds();
  return r;
}

std::string format_phantom_summary(const PhantomJob& job, const PhantomJobResult& r) {
  std::string s = fmt::format(
      "naris phantom: subject {}\n  CT {} voxels of {} (coronal slices along k), noise {:g} HU\n"
      "  seed in the naris: {:.2f},{:.2f},{:.2f} mm\n  time {:.2f} s\n  wrote {}",
      job.subject, dims_text(r.ct), spacing_text(r.ct), job.sampling.noise, r.seed[0], r.seed[1],
      r.seed[2], r.seconds, job.output.string());
  if (!job.exact_mask.empty())
    s += fmt::format("\n  wrote {} (exact airway, {} voxels of {})", job.exact_mask.string(),
                     dims_text(r.mask), spacing_text(r.mask));
  return s;
}

InterpolateJobResult run_interpolate_job(const InterpolateJob& job) {
  ensure_writable_folder(fs::absolute(job.output).parent_path());
  if (job.insert && job.spacing) fail("give the slices to insert or the target spacing, not both");
  if (job.insert && *job.insert < 0) fail("cannot insert {} slices: give 0 or more", *job.insert);
  if (job.spacing && !(*job.spacing > 0.0))
    fail("the target spacing must be positive (got {} mm)", *job.spacing);
  if (job.hsr.block < 2 || job.hsr.levels < 1 || job.hsr.iterations < 1)
    fail("HSR needs a block of at least 2 pixels, at least one level and one iteration");
  Stopwatch clock;
  VolumeInfo info;
  Volume<float> v = read_volume(job.input, &info);
  InterpolateJobResult r;
  r.before = v.frame;
  if (job.axis == "auto") {
    r.axis = static_cast<int>(std::max_element(v.frame.spacing.data(), v.frame.spacing.data() + 3) -
                              v.frame.spacing.data());
  } else if (job.axis == "i" || job.axis == "j" || job.axis == "k") {
    r.axis = job.axis[0] - 'i';
  } else {
    fail("slice axis '{}' not understood: give i, j, k or auto", job.axis);
  }
  if (v.dims()[r.axis] < 2)
    fail("{}: a single slice along {} cannot be interpolated; a volume needs at least two",
         job.input.string(), "ijk"[r.axis]);
  const double h = v.frame.spacing[r.axis];
  // By default down to the finest spacing: isotropic voxels when the plane is square.
  const double target = job.spacing ? *job.spacing : v.frame.spacing.minCoeff();
  r.inserted =
      job.insert ? *job.insert : std::max(0, static_cast<int>(std::lround(h / target)) - 1);
  r.mask = is_binary(v);
  // Labels are not intensities: HSR or a cross-fade would invent labels between two.
  if (const std::vector<float> labels = r.mask ? std::vector<float>{} : map_labels(v);
      !labels.empty()) {
    r.labels = static_cast<int>(labels.size());
    const Volume<float> out = interpolate_label_map(v, labels, r.axis, r.inserted, job.threads);
    r.after = out.frame;
    Volume<std::uint8_t> map;
    map.frame = out.frame;
    map.values.assign(out.values.begin(), out.values.end());
    write_labelmap_nrrd(map, job.output);
    r.seconds = clock.seconds();
    return r;
  }
  if (job.method == SliceMethod::shape && !r.mask) {
    // Shape-based interpolation blends distance maps of segmented slices: the gray values are
    // segmented first at the air threshold, and the result is an airway labelmap.
    r.binarized_at = air_threshold(v);
    for (float& x : v.values) x = x < *r.binarized_at ? 1.0f : 0.0f;
    r.mask = true;
  }
  const Volume<float> out =
      interpolate_slices(v, r.axis, r.inserted, job.method, job.hsr, job.threads);
  r.after = out.frame;
  if (r.mask) {
    write_labelmap_nrrd(to_mask(out), job.output);
  } else {
    write_ct_nrrd(out, job.output);
  }
  r.seconds = clock.seconds();
  return r;
}

std::string format_interpolate_summary(const InterpolateJob& job, const InterpolateJobResult& r) {
  static const char* names[] = {"hsr", "linear", "shape"};
  std::string kind = r.mask ? "mask" : "gray values";
  if (r.binarized_at) kind = fmt::format("gray values segmented below {:.1f} HU", *r.binarized_at);
  if (r.labels) kind = fmt::format("label map of {} labels, shape-based label by label", r.labels);
  return fmt::format(
      "naris interpolate: {} ({}), method {}\n  {} → {} voxels; spacing {} → {}\n"
      "  {} slice(s) inserted between each pair along {}\n  time {:.2f} s\n  wrote {}",
      job.input.filename().string(), kind, r.labels ? "shape" : names[static_cast<int>(job.method)],
      dims_text(r.before), dims_text(r.after), spacing_text(r.before), spacing_text(r.after),
      r.inserted, "ijk"[r.axis], r.seconds, job.output.string());
}

namespace {

// Where a seed the nasal airway does not hold lies (null: in the airway).
const char* where_it_lies(AirwayRegion region) {
  switch (region) {
    case AirwayRegion::airway:
      return nullptr;
    case AirwayRegion::tissue:
    case AirwayRegion::masked:
      return "in tissue or bone";
    case AirwayRegion::sinus:
      return "in a paranasal sinus";
    case AirwayRegion::room:
      return "outside the body, in the room air";
    case AirwayRegion::excluded:
      return "in the nasal airway but not in the part kept (the other side, or behind the "
             "choana: see --side and --nasopharynx)";
    case AirwayRegion::enclosed:
      return "in air the nares do not reach";
  }
  return nullptr;
}

// The airway's sidecar: what the segmentation found, and the planes for the mesher's "auto".
Json nasal_sidecar(const SegmentJob& job, const NasalAirway& nasal, const fs::path& regions) {
  Json sidecar{{"airway", "nasal"},
               {"side", nasal_side_name(job.side)},
               {"nasopharynx", job.keep_nasopharynx ? "keep" : "cut"},
               {"threshold_hu", significant(nasal.threshold, 5)},
               {"wall_hu", significant(nasal.wall_level, 5)},
               {"volume_ml", significant(nasal.volume_ml, 5)},
               {"wall_layer_ml", significant(nasal.wall_layer_ml, 5)},
               {"sinus_ml", significant(nasal.sinus_ml, 5)},
               {"sinuses", nasal.sinuses},
               {"room_ml", significant(nasal.room_ml, 5)},
               {"masked_voxels", nasal.masked_voxels},
               {"inlet", nasal.inlet},
               {"outlet", nasal.outlet.empty() ? Json() : Json(nasal.outlet)},
               {"choana_slice", nasal.choana ? Json(*nasal.choana) : Json()},
               {"ap_axis", std::string(1, static_cast<char>('i' + nasal.ap_axis))}};
  Json& nares = sidecar["nares"] = Json::array();
  for (const Naris& n : nasal.nares)
    nares.push_back({{"side", n.right ? "right" : "left"},
                     {"opening_mm2", significant(n.area, 5)},
                     {"centre_mm", {n.centre[0], n.centre[1], n.centre[2]}},
                     {"normal", {n.normal[0], n.normal[1], n.normal[2]}}});
  sidecar["regions"] = regions.filename().string();
  return sidecar;
}

// segment --airway nasal: the airway, checked against the seeds, with its sidecar and regions.
void run_nasal_airway(const SegmentJob& job, const Volume<float>& ct, SegmentJobResult& r) {
  NasalAirwayOptions options;
  if (job.threshold != "auto") options.threshold = r.threshold;
  options.side = job.side;
  options.keep_nasopharynx = job.keep_nasopharynx;
  NasalAirway nasal = segment_nasal_airway(ct, options);
  for (const auto& text : job.seeds) {
    const Voxel v = parse_seed(text, ct.frame);
    const std::size_t q = ct.frame.index(v[0], v[1], v[2]);
    if (const char* where = where_it_lies(static_cast<AirwayRegion>(nasal.regions.values[q])))
      fail("seed '{}' (voxel {},{},{}, {:.0f} HU) lies {}", text, v[0], v[1], v[2], ct.values[q],
           where);
  }
  r.threshold = nasal.threshold;
  r.components = {
      1,
      static_cast<std::size_t>(std::count(nasal.mask.values.begin(), nasal.mask.values.end(), 1)),
      0};
  r.frame = nasal.mask.frame;
  r.inside = InsideRule::below;
  const fs::path regions = segmentation_regions(job.output);
  write_labelmap_nrrd(nasal.mask, job.output);
  write_labelmap_nrrd(nasal.regions, regions);
  write_json_file(segmentation_sidecar(job.output), nasal_sidecar(job, nasal, regions));
  nasal.mask = {};
  nasal.regions = {};
  r.nasal = std::move(nasal);
}

}  // namespace

SegmentJobResult run_segment_job(const SegmentJob& job) {
  ensure_writable_folder(fs::absolute(job.output).parent_path());
  if (job.decimate < 1 || job.decimate > 16)
    fail("decimation factor {} is not in 1 … 16", job.decimate);
  Stopwatch clock;
  VolumeInfo info;
  Volume<float> ct = read_volume(job.input, &info);
  SegmentJobResult r;
  r.format = info.format;
  // A labelmap (from shape-based interpolation, or a segmentation to clean up) is grown from
  // the seeds as it is: its airway is the label 1.
  const bool labelmap = is_binary(ct);
  InsideRule inside = job.inside;
  if (job.decimate > 1) ct = decimate_in_plane(ct, job.decimate);
  if (!job.rotate.empty()) {
    const auto colon = job.rotate.find(':');
    const std::string axis = job.rotate.substr(0, colon);
    if (colon == std::string::npos || (axis != "i" && axis != "j" && axis != "k"))
      fail("rotation '{}' not understood: give AXIS:DEGREES with AXIS i, j or k", job.rotate);
    double degrees = 0.0;
    try {
      degrees = std::stod(job.rotate.substr(colon + 1));
    } catch (const std::exception&) {
      fail("rotation '{}': the angle is not a number", job.rotate);
    }
    // Voxels brought in from outside the scan are the densest value: never airway.
    ct = rotate_about_axis(ct, axis[0] - 'i', degrees, static_cast<float>(info.max_value));
  }
  if (job.threshold == "auto" && labelmap) {
    r.threshold = 0.5;
    inside = InsideRule::above;
  } else if (job.threshold == "auto") {
    r.threshold = air_threshold(ct);
  } else {
    try {
      std::size_t used = 0;
      r.threshold = std::stod(job.threshold, &used);
      if (used != job.threshold.size()) throw std::invalid_argument("trailing text");
    } catch (const std::exception&) {
      fail("threshold '{}' is neither a number nor 'auto'", job.threshold);
    }
  }
  if (!(r.threshold > info.min_value && r.threshold < info.max_value))
    fail("{}: threshold {} is outside the data range [{}, {}]: it selects nothing or everything",
         job.input.string(), r.threshold, info.min_value, info.max_value);
  if (job.airway == "nasal") {
    if (labelmap) fail("{}: --airway nasal needs a CT in HU, not a labelmap", job.input.string());
    if (inside != InsideRule::below) fail("--airway nasal: the airway is below the threshold");
    run_nasal_airway(job, ct, r);
    r.seconds = clock.seconds();
    return r;
  }
  if (job.airway != "any") fail("airway '{}' is neither 'any' nor 'nasal'", job.airway);
  std::vector<Voxel> seeds;
  for (const auto& s : job.seeds) seeds.push_back(parse_seed(s, ct.frame));
  Volume<std::uint8_t> mask = seeds.empty() ? threshold_mask(ct, r.threshold, inside)
                                            : grow_region(ct, r.threshold, inside, seeds);
  std::size_t voxels = 0;
  for (auto v : mask.values) voxels += v;
  if (voxels == 0) fail("{}: the threshold {} selects no voxel", job.input.string(), r.threshold);
  if (voxels == mask.values.size())
    fail(
        "{}: the threshold {} selects every voxel: nothing separates the airway (check the "
        "inside side)",
        job.input.string(), r.threshold);
  r.components = {1, voxels, 0};
  if (job.keep_largest) r.components = keep_largest_component(mask);
  r.frame = mask.frame;
  r.inside = inside;
  r.labelmap = labelmap;
  write_labelmap_nrrd(mask, job.output);
  r.seconds = clock.seconds();
  return r;
}

fs::path segmentation_sidecar(const fs::path& labelmap) {
  fs::path p = labelmap;
  if (p.extension() == ".gz") p.replace_extension();
  return p.replace_extension(".json");
}

fs::path segmentation_regions(const fs::path& labelmap) {
  fs::path p = segmentation_sidecar(labelmap);
  return p.replace_filename(p.stem().string() + "-regions.nrrd");
}

std::string format_segment_summary(const SegmentJob& job, const SegmentJobResult& r) {
  const double voxel_ml = r.frame.spacing.prod() / 1000.0;
  if (r.nasal) {
    const NasalAirway& a = *r.nasal;
    std::string nares;
    for (const Naris& n : a.nares)
      nares +=
          fmt::format("\n  {} naris: opening {:.1f} mm² at {:.1f},{:.1f},{:.1f} mm",
                      n.right ? "right" : "left", n.area, n.centre[0], n.centre[1], n.centre[2]);
    return fmt::format(
        "naris segment: {} ({}, {}), nasal airway, {} side(s), nasopharynx {}\n  threshold {:.1f} "
        "HU ({}), wall at {:.1f} HU\n  airway {:.2f} mL ({:.2f} mL of it the wall's layer); left "
        "out: {} sinus cavities ({:.1f} mL), room air {:.0f} "
        "mL{}{}\n  inlet {}\n  outlet {}\n  time {:.2f} s\n  wrote {}, {} and {}",
        job.input.filename().string(), dims_text(r.frame), spacing_text(r.frame),
        nasal_side_name(job.side), job.keep_nasopharynx ? "kept" : "cut", r.threshold,
        job.threshold == "auto" ? "automatic" : "given", a.wall_level, a.volume_ml, a.wall_layer_ml,
        a.sinuses, a.sinus_ml, a.room_ml,
        a.masked_voxels ? fmt::format("; {} masked voxels taken for tissue", a.masked_voxels) : "",
        nares, a.inlet, a.outlet.empty() ? "(none: give one to the mesher)" : a.outlet, r.seconds,
        job.output.string(), segmentation_sidecar(job.output).string(),
        segmentation_regions(job.output).string());
  }
  return fmt::format(
      "naris segment: {} ({}, {}, {})\n  threshold {:.1f} HU ({}), inside {}\n  airway {} voxels, "
      "{:.3f} mL; {} component(s), {} voxels dropped\n  time {:.2f} s\n  wrote {}",
      job.input.filename().string(), dims_text(r.frame), spacing_text(r.frame), r.format,
      r.threshold,
      r.labelmap                ? "labelmap"
      : job.threshold == "auto" ? "automatic"
                                : "given",
      inside_rule_name(r.inside), r.components.kept_voxels,
      static_cast<double>(r.components.kept_voxels) * voxel_ml, r.components.components,
      r.components.dropped_voxels, r.seconds, job.output.string());
}

}  // namespace naris
