#include "postproc/figures/canvas.h"

#include <cairo-svg.h>
#include <fmt/format.h>

#include <cmath>

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris::figures {

namespace {

cairo_surface_t* recording(int width, int height) {
  const cairo_rectangle_t extents{0.0, 0.0, static_cast<double>(width),
                                  static_cast<double>(height)};
  return cairo_recording_surface_create(CAIRO_CONTENT_COLOR_ALPHA, &extents);
}

// Replays the recording onto `target` and finishes it.
void replay(cairo_surface_t* recorded, cairo_surface_t* target) {
  cairo_t* cr = cairo_create(target);
  cairo_set_source_surface(cr, recorded, 0.0, 0.0);
  cairo_paint(cr);
  cairo_destroy(cr);
  cairo_surface_flush(target);
}

}  // namespace

Canvas::Canvas(int width, int height)
    : width_(width),
      height_(height),
      surface_(recording(width, height), &cairo_surface_destroy),
      context_(cairo_create(surface_.get()), &cairo_destroy) {
  cairo_set_source_rgb(cr(), 1, 1, 1);
  cairo_paint(cr());
  cairo_select_font_face(cr(), "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
}

void Canvas::text(double x, double y, const std::string& s, double size, double align_x,
                  double align_y) const {
  cairo_set_font_size(cr(), size);
  cairo_text_extents_t e;
  cairo_text_extents(cr(), s.c_str(), &e);
  cairo_move_to(cr(), x - align_x * e.width - e.x_bearing, y - align_y * e.height - e.y_bearing);
  cairo_show_text(cr(), s.c_str());
}

void Canvas::write_png(const std::filesystem::path& path) const {
  AtomicOutput out(path);
  std::unique_ptr<cairo_surface_t, void (*)(cairo_surface_t*)> image(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width_, height_), &cairo_surface_destroy);
  replay(surface_.get(), image.get());
  if (cairo_surface_write_to_png(image.get(), out.temp_path().c_str()) != CAIRO_STATUS_SUCCESS)
    fail("{}: cannot write the PNG", path.string());
  out.commit();
}

void Canvas::write_svg(const std::filesystem::path& path) const {
  AtomicOutput out(path);
  cairo_surface_t* svg = cairo_svg_surface_create(out.temp_path().c_str(), width_, height_);
  replay(surface_.get(), svg);
  cairo_surface_finish(svg);
  const cairo_status_t status = cairo_surface_status(svg);
  cairo_surface_destroy(svg);
  if (status != CAIRO_STATUS_SUCCESS) fail("{}: cannot write the SVG", path.string());
  out.commit();
}

std::array<double, 3> group_colour(int g) {
  static const std::array<double, 3> palette[] = {
      {0.84, 0.15, 0.16}, {0.12, 0.47, 0.71}, {0.17, 0.63, 0.17}, {1.00, 0.50, 0.05},
      {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29}, {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50}};
  return palette[static_cast<std::size_t>(g) % 8];
}

void group_legend(const Canvas& canvas, const std::vector<std::string>& groups, double x,
                  double y) {
  cairo_t* cr = canvas.cr();
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const auto c = group_colour(static_cast<int>(g));
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    cairo_rectangle(cr, x, y + 22.0 * static_cast<double>(g) - 6, 24, 12);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    canvas.text(x + 32, y + 22.0 * static_cast<double>(g), groups[g], 15, 0.0, 0.5);
  }
}

// A scale bar of a round length near a fifth of `span_mm`.
void scale_bar(const Canvas& canvas, double x, double y, double pixels_per_mm, double span_mm) {
  cairo_t* cr = canvas.cr();
  double length = std::pow(10.0, std::floor(std::log10(span_mm / 5.0)));
  for (double m : {5.0, 2.0})
    if (m * length <= span_mm / 5.0) {
      length *= m;
      break;
    }
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  cairo_set_line_width(cr, 3.0);
  cairo_move_to(cr, x, y);
  cairo_line_to(cr, x + length * pixels_per_mm, y);
  cairo_stroke(cr);
  canvas.text(x + 0.5 * length * pixels_per_mm, y + 8, fmt::format("{:g} mm", length), 14, 0.5,
              0.0);
}

}  // namespace naris::figures
