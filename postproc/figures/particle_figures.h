#pragma once
// Figures of particle paths (cairo, PNG): the paths over the airway drawn as a translucent
// shaded surface, seen along one axis (Figs. 4.14, 4.16, 4.18 of the dissertation), and the
// points where particles cross cross-section planes inside each plane's outline (Figs. 4.15,
// 4.17, 4.19). Coordinates in millimetres.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace naris::figures {

using Point3 = std::array<double, 3>;
using Point2 = std::array<double, 2>;

struct PathFigure {
  std::string title, caption;
  std::vector<std::array<Point3, 3>> surface;  // the airway wall
  std::vector<std::vector<Point3>> paths;
  std::vector<int> path_group;
  std::vector<std::string> groups;
  Point3 right{0, 1, 0}, up{0, 0, 1};  // the view: screen right and up (unit, orthogonal)
  std::string right_label = "y (mm)", up_label = "z (mm)";
};
void write_path_figure(const PathFigure& figure, const std::filesystem::path& path,
                       int width = 1400, int height = 900);

struct SectionPanel {
  std::string title;
  std::vector<std::array<Point2, 2>> outline;  // the wall's section, in-plane coordinates
  std::vector<Point2> points;
  std::vector<int> point_group;
};
struct CrossingFigure {
  std::string title, caption, u_label, v_label;
  std::vector<SectionPanel> panels;  // one scale for all
  std::vector<std::string> groups;
};
void write_crossing_figure(const CrossingFigure& figure, const std::filesystem::path& path,
                           int panel_size = 420);

}  // namespace naris::figures
