#pragma once
// The cross-section figure of section 4.3.1 (Figs. 4.6–4.11): speed as filled bands with contour
// lines in equal increments from 0 at the wall to the plane's maximum, the secondary (in-plane)
// velocity as arrows on a regular grid with a scale arrow, the wall's outline, a colour bar, and
// a caption; optionally the particles' crossing points coloured by release group. In-plane
// coordinates in millimetres, velocities in m/s. Written as PNG and SVG.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace naris::figures {

using Point2 = std::array<double, 2>;
using Polyline2 = std::vector<Point2>;

struct Arrow {
  Point2 at, vector;  // mm, m/s
};

struct SectionFigure {
  std::string title, caption;  // the caption may hold several lines ('\n')
  std::string u_label = "u (mm)", v_label = "v (mm)";
  int levels = 15;                     // speed bands from 0 to max_speed
  double max_speed = 0.0, u_in = 0.0;  // m/s: the colour scale's top; the inlet speed
  std::vector<Polyline2> bands;        // closed polygons …
  std::vector<int> band;               // … and their band, 0 … levels − 1
  std::vector<Polyline2> contours;     // speed contour lines
  std::vector<Polyline2> outline;      // the wall, closed loops
  std::vector<Arrow> arrows;
  double arrow_spacing = 1.0;       // mm between grid arrows
  std::vector<Point2> crossings;    // particles crossing the plane …
  std::vector<int> crossing_group;  // … and their release group
  std::vector<std::string> groups;
  // The drawn extent (mm); empty: the outline's bounds. Set it to give panels one scale.
  std::array<double, 4> extent{0.0, 0.0, 0.0, 0.0};  // u0, u1, v0, v1
};

// Throws naris::Error when there is nothing to draw or a file cannot be written; `svg` may be
// empty; `width` 0: from the section's aspect.
void write_section_figure(const SectionFigure& figure, const std::filesystem::path& png,
                          const std::filesystem::path& svg = {}, int width = 0, int height = 960);

// Sections side by side (Figs. 4.12, 4.13): one millimetre scale, each panel centred on its
// section; one colour scale, the panels' bands having been cut to the same maximum speed (the
// first panel's max_speed), and one arrow scale. Each panel's title names it.
void write_section_grid(const std::vector<SectionFigure>& panels, const std::string& title,
                        const std::string& caption, const std::filesystem::path& png,
                        const std::filesystem::path& svg = {});

// The sequential colour map of the speed bands (viridis), t in [0, 1].
std::array<double, 3> speed_colour(double t);

}  // namespace naris::figures
