#pragma once
// Geometric preparation of a CT volume before segmentation (dissertation 4.2.3): in-plane
// decimation by an integer factor, and rotation about an axis (e.g. 30° in the sagittal plane
// to align the cavity with the grid).
#include "mesh/image/volume.h"

namespace naris {

// Averages factor×factor blocks of each slice (axes i and j); spacing grows by the factor.
// Trailing voxels that do not fill a block are dropped.
Volume<float> decimate_in_plane(const Volume<float>& v, int factor);

// Resamples v (trilinear) on a grid rotated by `degrees` about image axis `axis` (0, 1, 2) through
// the volume centre, same spacing, sized to hold the whole rotated volume; voxels outside the
// original are `fill`.
Volume<float> rotate_about_axis(const Volume<float>& v, int axis, double degrees, float fill);

}  // namespace naris
