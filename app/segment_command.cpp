// `naris segment`: airway labelmap from a CT volume (dissertation 4.2.2).
#include <fmt/format.h>

#include <memory>

#include "commands.h"
#include "core/error.h"
#include "core/log.h"
#include "image/read_volume.h"
#include "image/resample.h"
#include "image/segment.h"
#include "io/atomic_file.h"

namespace naris::app {

void add_segment_command(CLI::App& app) {
  struct Options {
    std::filesystem::path input, output = "airway.nrrd";
    std::string threshold = "auto", inside = "below";
    std::vector<std::string> seeds;
    bool all_components = false;
    std::string rotate;
    int decimate = 1;
  };
  auto o = std::make_shared<Options>();
  auto* cmd = app.add_subcommand(
      "segment",
      "Segment the airway of a CT volume: threshold (automatic: the HU histogram's valley nearest "
      "−1000), 26-connected region growing from seeds (or every voxel below the threshold), "
      "largest component; writes a labelmap NRRD that 3D Slicer opens");
  cmd->add_option("input", o->input, "CT volume (.nrrd, .nii, .mha, .vti or a DICOM folder)")
      ->required();
  cmd->add_option("--threshold", o->threshold, "HU threshold, or 'auto'")->capture_default_str();
  cmd->add_option("--inside", o->inside, "the airway is 'below' or 'above' the threshold")
      ->check(CLI::IsMember({"below", "above"}))
      ->capture_default_str();
  cmd->add_option("--seed", o->seeds,
                  "seed voxel i,j,k or point x,y,z mm in the airway; repeatable");
  cmd->add_flag("--all-components", o->all_components,
                "keep every component (default: the largest)");
  cmd->add_option("--rotate", o->rotate,
                  "rotate the volume first, AXIS:DEGREES about image axis i, j or k (e.g. i:30); "
                  "seeds in voxels then refer to the rotated grid, seeds in mm do not change");
  cmd->add_option("--decimate", o->decimate, "average N×N blocks of each slice first")
      ->check(CLI::Range(1, 16))
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output, "labelmap NRRD")->capture_default_str();
  cmd->callback([o] {
    ensure_writable_folder(std::filesystem::absolute(o->output).parent_path());
    Stopwatch clock;
    VolumeInfo info;
    Volume<float> ct = read_volume(o->input, &info);
    if (o->decimate > 1) ct = decimate_in_plane(ct, o->decimate);
    if (!o->rotate.empty()) {
      const auto colon = o->rotate.find(':');
      const std::string axis = o->rotate.substr(0, colon);
      if (colon == std::string::npos || (axis != "i" && axis != "j" && axis != "k"))
        fail("--rotate '{}' not understood: give AXIS:DEGREES with AXIS i, j or k", o->rotate);
      double degrees = 0.0;
      try {
        degrees = std::stod(o->rotate.substr(colon + 1));
      } catch (const std::exception&) {
        fail("--rotate '{}': the angle is not a number", o->rotate);
      }
      // Voxels brought in from outside the scan are the densest value: never airway.
      ct = rotate_about_axis(ct, axis[0] - 'i', degrees, static_cast<float>(info.max_value));
    }
    double threshold;
    if (o->threshold == "auto") {
      threshold = air_threshold(ct);
    } else {
      try {
        threshold = std::stod(o->threshold);
      } catch (const std::exception&) {
        fail("--threshold '{}' is neither a number nor 'auto'", o->threshold);
      }
    }
    const bool above = o->inside == "above";
    if (!(threshold > info.min_value && threshold < info.max_value))
      fail("{}: threshold {} is outside the data range [{}, {}]: it selects nothing or everything",
           o->input.string(), threshold, info.min_value, info.max_value);
    std::vector<Voxel> seeds;
    for (const auto& s : o->seeds) seeds.push_back(parse_seed(s, ct.frame));
    Volume<std::uint8_t> mask = seeds.empty() ? threshold_mask(ct, threshold, above)
                                              : grow_region(ct, threshold, above, seeds);
    std::size_t voxels = 0;
    for (auto v : mask.values) voxels += v;
    if (voxels == 0) fail("{}: the threshold {} selects no voxel", o->input.string(), threshold);
    if (voxels == mask.values.size())
      fail(
          "{}: the threshold {} selects every voxel: nothing separates the airway (check --inside)",
          o->input.string(), threshold);
    ComponentSummary components{1, voxels, 0};
    if (!o->all_components) components = keep_largest_component(mask);
    write_labelmap_nrrd(mask, o->output);
    const double voxel_ml = ct.frame.spacing.prod() / 1000.0;
    log_line(fmt::format(
        "naris segment: {} ({}×{}×{}, {})\n  threshold {:.1f} HU ({}), inside {}\n  airway {} "
        "voxels, "
        "{:.3f} mL; {} component(s), {} voxels dropped\n  time {:.2f} s\n  wrote {}",
        o->input.filename().string(), ct.dims()[0], ct.dims()[1], ct.dims()[2], info.format,
        threshold, o->threshold == "auto" ? "automatic" : "given", o->inside,
        components.kept_voxels, static_cast<double>(components.kept_voxels) * voxel_ml,
        components.components, components.dropped_voxels, clock.seconds(), o->output.string()));
  });
}

}  // namespace naris::app
