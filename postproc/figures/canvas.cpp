#include "postproc/figures/canvas.h"

#include "core/atomic_file.h"
#include "core/error.h"

namespace naris::figures {

Canvas::Canvas(int width, int height)
    : surface_(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height),
               &cairo_surface_destroy),
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
  if (cairo_surface_write_to_png(surface_.get(), out.temp_path().c_str()) != CAIRO_STATUS_SUCCESS)
    fail("{}: cannot write the PNG", path.string());
  out.commit();
}

}  // namespace naris::figures
