#pragma once
// A procedural CT phantom of one (right) human nasal cavity: the project's default case.
//
// Each coronal section (normal to the anterior–posterior axis, s mm behind the naris) is a union
// of capsules — straight segments thickened by a radius — whose positions and radii vary
// smoothly with s: the common meatus (nostril → vestibule → valve → main slit → choana →
// nasopharynx), three meatus branches from the lateral wall (inferior, middle, superior: the
// tissue between them is the turbinate-like folds) and a 1 mm olfactory slit at the roof.
// Keyframes were tuned so that the sections' areas and perimeters come close to Table 4.3 of the
// dissertation. The subject number perturbs turbinate sizes, meatus widths and a septal bulge;
// subject 3 has a partially obstructed middle meatus, like study 3.
//
// Sampling follows a clinical scan: thick coronal slices (3 mm, rectangular slice profile
// integrated over the thickness), 0.3 mm pixels (integrated over the pixel), HU values for air,
// soft tissue and bone, plus Gaussian noise. Coordinates are LPS millimetres; image axis i runs
// lateral (patient right), j superior, k posterior; k = 0 is the naris plane.
#include <array>
#include <cstdint>

#include "mesh/image/volume.h"

namespace naris {

struct PhantomSampling {
  double pixel = 0.3;      // in-plane pixel size (mm)
  double slice = 3.0;      // slice thickness and spacing (mm)
  double noise = 20.0;     // standard deviation of the Gaussian noise (HU)
  int subsamples = 3;      // per pixel side, for partial volume in the plane
  int slice_samples = 12;  // across the slice profile
};

class NasalPhantom {
 public:
  explicit NasalPhantom(int subject = 1);

  int subject() const { return subject_; }
  // Airway length from the naris (s = 0) to the posterior end of the volume (mm).
  double length() const { return 96.0; }

  // Signed "section distance" at lateral offset u (from the septum), height h (above the
  // floor) and depth s (behind the naris), in mm: negative in the airway, and away from it
  // roughly the in-plane distance to the airway wall.
  double section_field(double u, double h, double s) const;
  bool in_airway(const Eigen::Vector3d& lps) const;

  // The frame of a scan with the given in-plane pixel and slice spacing covering the cavity.
  ImageFrame frame(double pixel, double slice) const;
  // A point in the airway on the naris plane (LPS mm): a seed for region growing.
  Eigen::Vector3d seed_point() const;

  // Area (mm²) and perimeter (mm) of the airway section at depth s, measured on a grid of the
  // given step (marching squares).
  std::array<double, 2> section_area_perimeter(double s, double step = 0.02) const;

  struct Keyframe;  // the parameters of the section at one depth (defined in phantom.cpp)

  // How this subject departs from the reference anatomy (subject 1: not at all).
  struct Variation {
    double branch_scale[3] = {1.0, 1.0, 1.0};  // inferior, middle, superior meatus lengths
    double meatus_width_scale = 1.0;
    double septal_bulge = 0.0;  // mm into the common meatus
    double obstruction = 1.0;   // middle meatus radius factor between s = 50 and 70
  };
  const Variation& variation() const { return variation_; }

 private:
  int subject_;
  Variation variation_;
};

// The CT scan of the phantom (HU, float) sampled as described above; threads over slices.
Volume<float> render_phantom_ct(const NasalPhantom& phantom, const PhantomSampling& sampling,
                                int threads = 0);

// The exact airway (point samples at voxel centres) on any grid.
Volume<std::uint8_t> phantom_mask(const NasalPhantom& phantom, const ImageFrame& grid);

// Dice coefficient 2|A∩B| / (|A|+|B|) of two masks on the same grid.
double dice(const Volume<std::uint8_t>& a, const Volume<std::uint8_t>& b);

}  // namespace naris
