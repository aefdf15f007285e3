#pragma once
// Slice interpolation of a volume along its thick axis (dissertation 2, 4.2.2): k new slices
// between each pair of acquired slices, by HSR or by the linear / shape-based baselines.
#include <string>
#include <vector>

#include "mesh/image/hsr.h"
#include "mesh/image/volume.h"

namespace naris {

enum class SliceMethod { hsr, linear, shape };
SliceMethod parse_slice_method(const std::string& name);

// Inserts `k` slices between consecutive slices along `axis` (0, 1, 2); the spacing along the
// axis shrinks by k + 1. Masks (0/1 values) come back as 0/1 (thresholded at one half). Slice
// pairs are processed in parallel on `threads` threads (0: every core).
Volume<float> interpolate_slices(const Volume<float>& v, int axis, int k, SliceMethod method,
                                 const HsrOptions& hsr = {}, int threads = 0);

// The non-zero labels of a label map (integer labels 0 … 255, more than one of them non-zero:
// 3D Slicer's multi-segment maps, 0 the background); empty for anything else.
std::vector<float> map_labels(const Volume<float>& v);

// Shape-based interpolation of a label map with these `labels`, label by label: each new voxel
// takes the label whose interpolated signed distance is the most inside, or 0 where none is.
Volume<float> interpolate_label_map(const Volume<float>& v, const std::vector<float>& labels,
                                    int axis, int k, int threads = 0);

// Slice `index` across `axis` as a 2D image (and back).
Image2D slice_across(const Volume<float>& v, int axis, int index);
void set_slice_across(Volume<float>& v, int axis, int index, const Image2D& im);

}  // namespace naris
