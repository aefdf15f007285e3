#pragma once
// A white image with a cairo context, for the figures: text placed by its alignment, and the
// PNG written through an AtomicOutput.
#include <cairo.h>

#include <filesystem>
#include <memory>
#include <string>

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

 private:
  std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> surface_;
  std::unique_ptr<cairo_t, void (*)(cairo_t*)> context_;
};

}  // namespace naris::figures
