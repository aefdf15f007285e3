#pragma once
// Exact Euclidean distance transforms on a voxel grid (Felzenszwalb & Huttenlocher 2012: one
// lower envelope of parabolas per grid line, axis after axis), in millimetres with the frame's
// spacing. Linear in the voxel count; the morphology of the nasal-airway segmentation is built
// on them (balls of any radius cost the same).
#include <cstdint>
#include <span>
#include <vector>

#include "mesh/image/volume.h"

namespace naris {

// What lies outside the volume: nothing (never nearest) or the target set itself.
enum class OutsideIs { nothing, target };

// Squared distance (mm²) from every voxel centre to the nearest voxel centre where `target` is
// non-zero (0 on target voxels; +inf when there is no target at all).
std::vector<float> squared_distance(const ImageFrame& frame, std::span<const std::uint8_t> target,
                                    OutsideIs outside = OutsideIs::nothing, int threads = 0);

}  // namespace naris
