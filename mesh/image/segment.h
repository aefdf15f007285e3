#pragma once
// Segmentation of the airway from CT (dissertation 4.2.2): a threshold from the HU histogram,
// 26-connected region growing from seed voxels, keep-largest-component, and the labelmap
// written as NRRD (image/write_volume.h) for 3D Slicer. Memory is one byte per voxel beyond the
// image.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mesh/image/inside_rule.h"
#include "mesh/image/volume.h"

namespace naris {

// The local minimum of the smoothed histogram nearest to −1000 HU: the valley between air and
// tissue. Throws naris::Error when the histogram has no valley (no air, or a constant image).
double air_threshold(const Volume<float>& ct);

using Voxel = std::array<int, 3>;

// "i,j,k" (voxel indices) or "x,y,z mm" / "x,y,z" with the mm suffix (physical millimetres).
Voxel parse_seed(const std::string& text, const ImageFrame& frame);

// The 26-connected region of voxels inside by `side` (below or above the threshold) reached
// from the seeds. Throws naris::Error naming a seed outside the volume or not inside.
Volume<std::uint8_t> grow_region(const Volume<float>& image, double threshold, InsideRule side,
                                 const std::vector<Voxel>& seeds);

// Every voxel inside by `side` as a mask, no connectivity imposed.
Volume<std::uint8_t> threshold_mask(const Volume<float>& image, double threshold, InsideRule side);

struct ComponentSummary {
  std::size_t components = 0;
  std::size_t kept_voxels = 0;
  std::size_t dropped_voxels = 0;
};
// Keeps only the largest 26-connected component of a 0/1 mask.
ComponentSummary keep_largest_component(Volume<std::uint8_t>& mask);

}  // namespace naris
