#pragma once
// The image stages before the mesher as library calls, shared by their subcommands and by
// `naris run`: the CT phantom, slice interpolation and segmentation. Each checks its inputs
// before the long work, writes its file atomically and returns what its summary reports.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "mesh/image/hsr.h"
#include "mesh/image/interpolate_slices.h"
#include "mesh/image/nasal_airway.h"
#include "mesh/image/phantom.h"
#include "mesh/image/segment.h"

namespace naris {

struct PhantomJob {
  int subject = 1;
  PhantomSampling sampling;
  std::filesystem::path output = "ct.nrrd";
  // The exact airway, point-sampled on the scan's in-plane grid with slices `mask_spacing`
  // apart (empty path: not written).
  std::filesystem::path exact_mask;
  double mask_spacing = 0.3;
};
struct PhantomJobResult {
  ImageFrame ct, mask;
  Eigen::Vector3d seed;
  double seconds = 0.0;
};
PhantomJobResult run_phantom_job(const PhantomJob& job);
std::string format_phantom_summary(const PhantomJob& job, const PhantomJobResult& r);

struct InterpolateJob {
  std::filesystem::path input, output = "interpolated.nrrd";
  std::string axis = "auto";      // i, j, k or auto (the coarsest axis)
  std::optional<int> insert;      // slices inserted between each acquired pair, or
  std::optional<double> spacing;  // the target spacing along the axis (mm)
  SliceMethod method = SliceMethod::hsr;
  HsrOptions hsr;
  int threads = 0;
};
struct InterpolateJobResult {
  int axis = 2, inserted = 0;
  bool mask = false;
  int labels = 0;  // a label map's non-zero labels (interpolated label by label)
  std::optional<double> binarized_at;  // shape-based on gray values: the air threshold used
  ImageFrame before, after;
  double seconds = 0.0;
};
InterpolateJobResult run_interpolate_job(const InterpolateJob& job);
std::string format_interpolate_summary(const InterpolateJob& job, const InterpolateJobResult& r);

struct SegmentJob {
  std::filesystem::path input, output = "airway.nrrd";
  std::string threshold = "auto";         // HU, or auto: the histogram valley nearest −1000
  InsideRule inside = InsideRule::below;  // the threshold's side
  std::vector<std::string> seeds;  // "i,j,k" or "x,y,z mm"; none: every voxel past the threshold
  bool keep_largest = true;
  std::string rotate;  // AXIS:DEGREES, AXIS one of i, j, k
  int decimate = 1;
  // "any": the region grown from the seeds; "nasal": the nasal airway of a head CT, found
  // without seeds (nasal_airway.h), with its inlet and outlet planes in <output>.json.
  std::string airway = "any";
  NasalSide side = NasalSide::right;
  bool keep_nasopharynx = false;
};
struct SegmentJobResult {
  std::string format;
  ImageFrame frame;
  double threshold = 0.0;
  InsideRule inside = InsideRule::below;
  bool labelmap = false;
  ComponentSummary components;
  std::optional<NasalAirway> nasal;  // with airway "nasal" (its mask moved out)
  double seconds = 0.0;
};
// The sidecar of a segmentation: <output without its extension>.json.
std::filesystem::path segmentation_sidecar(const std::filesystem::path& labelmap);
// What every voxel became (AirwayRegion): <output without its extension>-regions.nrrd.
std::filesystem::path segmentation_regions(const std::filesystem::path& labelmap);
SegmentJobResult run_segment_job(const SegmentJob& job);
std::string format_segment_summary(const SegmentJob& job, const SegmentJobResult& r);

}  // namespace naris
