#include "mesh/patches/outlet_extension.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace naris {

OutletExtension::OutletExtension(const mve::FieldSource& base, const std::vector<Cut>& cuts,
                                 const mve::MveOptions& options, double length_mm,
                                 const std::string& patch)
    : base_(base), frame_(base.frame()), cuts_(cuts) {
  const auto cut =
      std::find_if(cuts_.begin(), cuts_.end(), [&](const Cut& c) { return c.patch == patch; });
  if (cut == cuts_.end()) fail("an {} extension needs an {} plane", patch, patch);
  if (!(length_mm > 0.0) || !std::isfinite(length_mm))
    fail("the {} extension is {} mm: give a positive length", patch, length_mm);
  // prepare_cuts made a plane along an image axis a side of the crop box.
  const auto side = std::find(options.side_patch.begin(), options.side_patch.end(), patch);
  if (side == options.side_patch.end())
    fail(
        "the {} plane '{}' is oblique: an extension needs a plane along an image axis (an index "
        "plane such as j=285, or p=…;n=… with n along an axis)",
        patch, cut->plane.text);
  const int s = static_cast<int>(side - options.side_patch.begin());
  axis_ = s / 2;
  const bool kept_above = s % 2 == 0;
  const int n = base.frame().dims[axis_];
  voxels_ = static_cast<int>(std::lround(length_mm / frame_.spacing[axis_]));
  if (voxels_ < 1)
    fail("the {} extension of {} mm is shorter than a voxel ({} mm)", patch, length_mm,
         frame_.spacing[axis_]);
  int at_here = 0;
  // The base's voxel planes from the cut to its far side are kept as they are.
  if (kept_above) {
    first_ = options.crop.lo[axis_];
    last_ = n - 1;
    shift_ = voxels_ - first_;
    at_here = 0;
  } else {
    first_ = 0;
    last_ = options.crop.hi[axis_];
    shift_ = 0;
    at_here = last_ + voxels_;
  }
  frame_.dims[axis_] = last_ - first_ + 1 + voxels_;
  frame_.origin -= shift_ * frame_.spacing[axis_] * frame_.direction.col(axis_);
  const char name = static_cast<char>('i' + axis_);
  for (Cut& c : cuts_) {
    if (&c == &*cut) {
      c.plane = parse_cut_plane(fmt::format("{}={}", name, at_here));
      c.plane.text = fmt::format("{} extended by {} voxels", cut->plane.text, voxels_);
    } else if (c.plane.index_plane && c.plane.axis == axis_) {
      c.plane.index += shift_;
    }
  }
}

int OutletExtension::source_index(int x) const {
  return std::clamp(x - shift_, first_, last_);
}

void OutletExtension::read_slice(int k, std::span<float> out) const {
  if (axis_ == 2) {
    base_.read_slice(source_index(k), out);
    return;
  }
  const auto& d = base_.frame().dims;
  slice_.resize(static_cast<std::size_t>(d[0]) * d[1]);
  base_.read_slice(k, slice_);
  const int ni = frame_.dims[0], nj = frame_.dims[1];
  for (int j = 0; j < nj; ++j)
    for (int i = 0; i < ni; ++i) {
      const int si = axis_ == 0 ? source_index(i) : i;
      const int sj = axis_ == 1 ? source_index(j) : j;
      out[static_cast<std::size_t>(j) * ni + i] = slice_[static_cast<std::size_t>(sj) * d[0] + si];
    }
}

}  // namespace naris
