#pragma once
// A section as the figure of section 4.3.1 draws it (postproc/figures/section_figure.h): the
// plane seen from the anterior, its speed bands and contours cut by VTK's banded contour filter,
// the secondary velocity probed on a regular grid, the wall, and the particles' crossings.
#include <filesystem>
#include <string>
#include <vector>

#include "postproc/figures/section_figure.h"
#include "postproc/planes/sections.h"

namespace naris::planes {

struct DrawingOptions {
  int levels = 15;         // speed bands from 0 at the wall to max_speed
  int arrows_across = 25;  // secondary-velocity arrows across the larger extent
  double u_in = 1.0;       // m/s, for the caption
  double max_speed = 0.0;  // the colour scale's top (m/s); 0: the section's own maximum
};

// A particle crossing a plane (mm) and its release group.
struct Crossing {
  Eigen::Vector3d x;
  int group;
};
// crossings.csv of naris trace: the points and their groups (numbered in order of appearance
// into `groups`). Throws naris::Error for a missing or malformed file.
std::vector<Crossing> read_crossings(const std::filesystem::path& path,
                                     std::vector<std::string>& groups);

// The figure of `s`; the crossings that lie on its plane are drawn.
figures::SectionFigure section_figure(const Section& s, const DrawingOptions& options,
                                      const std::vector<Crossing>& crossings = {},
                                      const std::vector<std::string>& groups = {});

}  // namespace naris::planes
