#include "postproc/figures/line_plot.h"

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/atomic_file.h"
#include "core/error.h"
#include "postproc/figures/canvas.h"

namespace naris::figures {
namespace {

// Round tick spacing: 1, 2 or 5 × 10^k giving about `count` ticks.
double tick_step(double span, int count) {
  const double raw = span / count;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * p) return m * p;
  return 10.0 * p;
}

}  // namespace

void write_png(const LinePlot& plot, const std::filesystem::path& path, int width, int height) {
  double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
  for (const auto& s : plot.series)
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!std::isfinite(s.y[k])) continue;
      x0 = std::min(x0, s.x[k]), x1 = std::max(x1, s.x[k]);
      y0 = std::min(y0, s.y[k]), y1 = std::max(y1, s.y[k]);
    }
  if (!(x1 > x0)) fail("{}: nothing to plot", path.string());
  if (!(y1 > y0)) y0 -= 1.0, y1 += 1.0;
  const double pad = 0.06 * (y1 - y0);
  y0 -= pad, y1 += pad;

  const Canvas canvas(width, height);
  cairo_t* cr = canvas.cr();
  const double left = 90, right = width - 30, top = 50, bottom = height - 70;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * (right - left); };
  auto py = [&](double y) { return bottom - (y - y0) / (y1 - y0) * (bottom - top); };

  auto text = [&](double x, double y, const std::string& s, double size, double align_x,
                  double align_y) { canvas.text(x, y, s, size, align_x, align_y); };

  // Grid, ticks and labels.
  cairo_set_line_width(cr, 1.0);
  const double dx = tick_step(x1 - x0, 8), dy = tick_step(y1 - y0, 6);
  for (double t = std::ceil(x0 / dx) * dx; t <= x1 + 1e-9 * dx; t += dx) {
    cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
    cairo_move_to(cr, px(t), top);
    cairo_line_to(cr, px(t), bottom);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    text(px(t), bottom + 8, fmt::format("{:g}", std::abs(t) < 1e-12 ? 0.0 : t), 13, 0.5, 0.0);
  }
  for (double t = std::ceil(y0 / dy) * dy; t <= y1 + 1e-9 * dy; t += dy) {
    cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
    cairo_move_to(cr, left, py(t));
    cairo_line_to(cr, right, py(t));
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
    text(left - 8, py(t), fmt::format("{:g}", std::abs(t) < 1e-12 ? 0.0 : t), 13, 1.0, 0.5);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_rectangle(cr, left, top, right - left, bottom - top);
  cairo_stroke(cr);
  text(0.5 * (left + right), height - 22, plot.x_label, 15, 0.5, 0.5);
  text(0.5 * (left + right), 24, plot.title, 17, 0.5, 0.5);
  cairo_save(cr);
  cairo_translate(cr, 22, 0.5 * (top + bottom));
  cairo_rotate(cr, -M_PI / 2);
  text(0, 0, plot.y_label, 15, 0.5, 0.5);
  cairo_restore(cr);

  // Series, clipped to the frame.
  cairo_save(cr);
  cairo_rectangle(cr, left, top, right - left, bottom - top);
  cairo_clip(cr);
  cairo_set_line_width(cr, 2.0);
  for (const auto& s : plot.series) {
    cairo_set_source_rgb(cr, s.rgb[0], s.rgb[1], s.rgb[2]);
    const double dash[] = {8.0, 5.0};
    cairo_set_dash(cr, dash, s.dashed ? 2 : 0, 0);
    bool started = false;
    for (std::size_t k = 0; k < s.x.size(); ++k) {
      if (!std::isfinite(s.y[k])) {
        started = false;
        continue;
      }
      if (started)
        cairo_line_to(cr, px(s.x[k]), py(s.y[k]));
      else
        cairo_move_to(cr, px(s.x[k]), py(s.y[k]));
      started = true;
    }
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
    for (std::size_t k : s.markers) {
      if (k >= s.x.size() || !std::isfinite(s.y[k])) continue;
      cairo_arc(cr, px(s.x[k]), py(s.y[k]), 6.0, 0.0, 2.0 * M_PI);
      cairo_fill(cr);
    }
  }
  cairo_set_dash(cr, nullptr, 0, 0);
  cairo_restore(cr);

  // The event arrow, pointing down onto the axis.
  if (plot.arrow_at_x) {
    const double ax = px(*plot.arrow_at_x);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_set_line_width(cr, 2.0);
    cairo_move_to(cr, ax, top + 8);
    cairo_line_to(cr, ax, top + 48);
    cairo_stroke(cr);
    cairo_move_to(cr, ax, top + 56);
    cairo_line_to(cr, ax - 6, top + 44);
    cairo_line_to(cr, ax + 6, top + 44);
    cairo_close_path(cr);
    cairo_fill(cr);
    if (!plot.arrow_label.empty()) text(ax + 8, top + 20, plot.arrow_label, 13, 0.0, 0.5);
  }

  // Legend, inside the frame's lower right corner, as wide as its longest label.
  double label_width = 0.0;
  cairo_set_font_size(cr, 13);
  for (const auto& s : plot.series) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.label.c_str(), &e);
    label_width = std::max(label_width, e.x_advance);
  }
  const double lx = right - label_width - 62;
  double ly = bottom - 20.0 * static_cast<double>(plot.series.size()) - 6;
  for (const auto& s : plot.series) {
    cairo_set_source_rgb(cr, s.rgb[0], s.rgb[1], s.rgb[2]);
    const double dash[] = {8.0, 5.0};
    cairo_set_dash(cr, dash, s.dashed ? 2 : 0, 0);
    cairo_move_to(cr, lx, ly);
    cairo_line_to(cr, lx + 40, ly);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0);
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    text(lx + 48, ly, s.label, 13, 0.0, 0.5);
    ly += 20;
  }

  canvas.write_png(path);
}

}  // namespace naris::figures
