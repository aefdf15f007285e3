#pragma once
// Line plots as PNG (cairo): the response figures of chapter 5 and profiles along the airway.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace naris::figures {

struct Series {
  std::string label;
  std::vector<double> x, y;
  bool dashed = false;
  std::array<double, 3> rgb{0.0, 0.0, 0.0};
  std::vector<std::size_t> markers;  // points drawn as circles (a minimum, an event)
};

struct LinePlot {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  std::optional<double> arrow_at_x;  // a vertical arrow marking an event (stimulus onset)
  std::string arrow_label;
};

void write_png(const LinePlot& plot, const std::filesystem::path& path, int width = 960,
               int height = 540);

}  // namespace naris::figures
