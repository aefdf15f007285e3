#pragma once
// The length of a section's outline that means something on a voxel mesh. A voxel outline is a
// staircase (or, with MVE's facets, nearly one): its length tends to 4/π (or ~1.05) times the
// smooth curve's and never improves with resolution. The smoothed length resamples each closed
// loop at equal arc length and convolves the points with a Gaussian of width σ (a voxel scale)
// along the loop, which removes the steps and shrinks a circle of radius R only by
// ≈ σ²/(2R²) (docs/method/planes.md).
#include <Eigen/Dense>
#include <vector>

namespace naris::planes {

using Loop = std::vector<Eigen::Vector3d>;  // closed: the last point joins the first

double loop_length(const Loop& loop);
// σ is capped at a sixteenth of the loop's length, so tiny loops keep their shape.
double smoothed_loop_length(const Loop& loop, double sigma);

}  // namespace naris::planes
