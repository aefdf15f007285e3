#pragma once
// A white page with a cairo context, for the figures: text placed by its alignment. The drawing
// is recorded, so the same figure is written as PNG (pixels) and as SVG (vectors, for papers),
// each through an AtomicOutput.
#include <cairo.h>

#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace naris::figures {

class Canvas {
 public:
  Canvas(int width, int height);
  cairo_t* cr() const { return context_.get(); }
  // `s` at (x, y), aligned by (align_x, align_y): 0 left/top, 0.5 centre, 1 right/bottom.
  void text(double x, double y, const std::string& s, double size, double align_x,
            double align_y) const;
  // Throws naris::Error when the file cannot be written.
  void write_png(const std::filesystem::path& path) const;
  void write_svg(const std::filesystem::path& path) const;

 private:
  int width_, height_;
  std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> surface_;
  std::unique_ptr<cairo_t, void (*)(cairo_t*)> context_;
};

// The colour of group g (a qualitative palette).
std::array<double, 3> group_colour(int g);
// A swatch and the name of each group, one row per group from (x, y).
void group_legend(const Canvas& canvas, const std::vector<std::string>& groups, double x, double y);
// A scale bar of a round length near a fifth of `span_mm`, from (x, y).
void scale_bar(const Canvas& canvas, double x, double y, double pixels_per_mm, double span_mm);

}  // namespace naris::figures
