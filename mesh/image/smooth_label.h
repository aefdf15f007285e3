#pragma once
// A smooth wall for a labelmap (docs/method/mesher.md, "Smooth walls"): the label's signed
// distance, smoothed by a Gaussian and then held on each voxel's own side of the level zero, so
// that no voxel changes from inside to outside or back. The mesher's cube configurations (and so
// the mesh's topology, its conformity and its thin passages) are those of the labelmap; only the
// isopoints move from edge midpoints onto a smooth surface.
#include <cstdint>

#include "mesh/image/volume.h"

namespace naris {

struct SmoothLabelOptions {
  double sigma = 1.0;   // Gaussian width, in voxels of the finest axis (isotropic in mm)
  double margin = 0.1;  // the level zero keeps this fraction of a voxel from every voxel centre
  int threads = 0;
};

// The field (mm; inside above 0) whose level zero is the smoothed wall of `mask` (non-zero:
// inside). Throws naris::Error for an empty or full mask or a non-positive sigma or margin.
Volume<float> smooth_label_field(const Volume<std::uint8_t>& mask,
                                 const SmoothLabelOptions& options = {});

}  // namespace naris
