#include "postproc/figures/section_figure.h"

#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "postproc/figures/canvas.h"

namespace naris::figures {
namespace {

// 1, 2 or 5 × 10^k, at most x.
double round_down(double x) {
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * p <= x) return m * p;
  return p;
}

void arrow_shape(cairo_t* cr, double x0, double y0, double x1, double y1, double head) {
  const double dx = x1 - x0, dy = y1 - y0, l = std::hypot(dx, dy);
  if (!(l > 0.5)) return;
  const double ux = dx / l, uy = dy / l, h = std::min(head, 0.45 * l);
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x1 - 0.6 * h * ux, y1 - 0.6 * h * uy);
  cairo_stroke(cr);
  cairo_move_to(cr, x1, y1);
  cairo_line_to(cr, x1 - h * ux + 0.4 * h * uy, y1 - h * uy - 0.4 * h * ux);
  cairo_line_to(cr, x1 - h * ux - 0.4 * h * uy, y1 - h * uy + 0.4 * h * ux);
  cairo_close_path(cr);
  cairo_fill(cr);
}

}  // namespace

std::array<double, 3> speed_colour(double t) {
  static const std::array<double, 3> stops[] = {
      {0.267, 0.005, 0.329}, {0.283, 0.141, 0.458}, {0.254, 0.265, 0.530}, {0.207, 0.372, 0.553},
      {0.164, 0.471, 0.558}, {0.128, 0.567, 0.551}, {0.135, 0.659, 0.518}, {0.267, 0.749, 0.441},
      {0.478, 0.821, 0.318}, {0.741, 0.873, 0.150}, {0.993, 0.906, 0.144}};
  t = std::clamp(t, 0.0, 1.0) * 10.0;
  const int i = std::min(9, static_cast<int>(t));
  const double f = t - i;
  std::array<double, 3> c;
  for (int k = 0; k < 3; ++k)
    c[static_cast<std::size_t>(k)] = (1.0 - f) * stops[i][static_cast<std::size_t>(k)] +
                                     f * stops[i + 1][static_cast<std::size_t>(k)];
  return c;
}

namespace {

using Extent = std::array<double, 4>;  // u0, u1, v0, v1 (mm)

// The outline's bounds, padded by 4 %.
Extent bounds(const SectionFigure& f) {
  if (f.extent[1] > f.extent[0] && f.extent[3] > f.extent[2]) return f.extent;
  Extent e{INFINITY, -INFINITY, INFINITY, -INFINITY};
  for (const auto& loop : f.outline)
    for (const Point2& p : loop)
      e = {std::min(e[0], p[0]), std::max(e[1], p[0]), std::min(e[2], p[1]), std::max(e[3], p[1])};
  const double pad = 0.04 * std::max(e[1] - e[0], e[3] - e[2]);
  return {e[0] - pad, e[1] + pad, e[2] - pad, e[3] + pad};
}

double longest_arrow(const SectionFigure& f) {
  double longest = 0.0;
  for (const Arrow& a : f.arrows) longest = std::max(longest, std::hypot(a.vector[0], a.vector[1]));
  return longest;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

// One section in the box (left, top, right, bottom) at `scale` px/mm over `e`, centred; arrows
// at `pixels_per_speed` px per m/s. Returns the drawn frame (x0, x1, y0, y1).
std::array<double, 4> draw_panel(const Canvas& canvas, const SectionFigure& f, const Extent& e,
                                 double left, double top, double right, double bottom, double scale,
                                 double pixels_per_speed, bool labels) {
  cairo_t* cr = canvas.cr();
  const double ox = left + 0.5 * ((right - left) - scale * (e[1] - e[0]));
  const double oy = bottom - 0.5 * ((bottom - top) - scale * (e[3] - e[2]));
  auto sx = [&](const Point2& p) { return ox + (p[0] - e[0]) * scale; };
  auto sy = [&](const Point2& p) { return oy - (p[1] - e[2]) * scale; };
  auto path = [&](const Polyline2& line, bool closed) {
    for (std::size_t k = 0; k < line.size(); ++k)
      (k == 0 ? cairo_move_to : cairo_line_to)(cr, sx(line[k]), sy(line[k]));
    if (closed) cairo_close_path(cr);
  };
  // Bands, each polygon filled with its band's colour and stroked thinly in it, so that no
  // hairline gaps show between neighbours.
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (std::size_t k = 0; k < f.bands.size(); ++k) {
    const auto c = speed_colour((f.band[k] + 0.5) / f.levels);
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    path(f.bands[k], true);
    cairo_fill_preserve(cr);
    cairo_set_line_width(cr, 0.6);
    cairo_stroke(cr);
  }
  cairo_set_source_rgba(cr, 0.0, 0.0, 0.0, 0.55);
  cairo_set_line_width(cr, 0.8);
  for (const auto& line : f.contours) {
    path(line, false);
    cairo_stroke(cr);
  }
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_set_line_width(cr, 2.0);
  for (const auto& loop : f.outline) {
    path(loop, true);
    cairo_stroke(cr);
  }
  for (int pass = 0; pass < 2 && pixels_per_speed > 0.0; ++pass) {  // a white halo first
    const double grey = pass == 0 ? 1.0 : 0.0;
    cairo_set_source_rgb(cr, grey, grey, grey);
    cairo_set_line_width(cr, pass == 0 ? 3.0 : 1.2);
    for (const Arrow& a : f.arrows) {
      const double x = sx(a.at), y = sy(a.at);
      arrow_shape(cr, x, y, x + a.vector[0] * pixels_per_speed, y - a.vector[1] * pixels_per_speed,
                  pass == 0 ? 9.0 : 7.0);
    }
  }
  for (std::size_t k = 0; k < f.crossings.size(); ++k) {
    const auto c = group_colour(f.crossing_group[k]);
    cairo_arc(cr, sx(f.crossings[k]), sy(f.crossings[k]), 4.0, 0.0, 2.0 * M_PI);
    cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    cairo_set_line_width(cr, 2.0);
    cairo_stroke(cr);
  }
  // A frame with ticks in millimetres.
  cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
  cairo_set_line_width(cr, 1.0);
  const double fx0 = ox, fx1 = ox + scale * (e[1] - e[0]), fy0 = oy - scale * (e[3] - e[2]),
               fy1 = oy;
  cairo_rectangle(cr, fx0, fy0, fx1 - fx0, fy1 - fy0);
  cairo_stroke(cr);
  const double tick = round_down(std::max(e[1] - e[0], e[3] - e[2]) / 6.0);
  for (double u = std::ceil(e[0] / tick) * tick; u <= e[1]; u += tick) {
    const double x = sx({u, 0.0});
    cairo_move_to(cr, x, fy1);
    cairo_line_to(cr, x, fy1 + 6);
    cairo_stroke(cr);
    canvas.text(x, fy1 + 9, fmt::format("{:g}", std::round(u / tick) * tick + 0.0), 13, 0.5, 0.0);
  }
  for (double v = std::ceil(e[2] / tick) * tick; v <= e[3]; v += tick) {
    const double y = sy({0.0, v});
    cairo_move_to(cr, fx0, y);
    cairo_line_to(cr, fx0 - 6, y);
    cairo_stroke(cr);
    canvas.text(fx0 - 9, y, fmt::format("{:g}", std::round(v / tick) * tick + 0.0), 13, 1.0, 0.5);
  }
  if (labels) {
    canvas.text(0.5 * (fx0 + fx1), fy1 + 30, f.u_label, 15, 0.5, 0.0);
    cairo_save(cr);
    cairo_translate(cr, fx0 - 55, 0.5 * (fy0 + fy1));
    cairo_rotate(cr, -M_PI / 2.0);
    canvas.text(0, 0, f.v_label, 15, 0.5, 0.5);
    cairo_restore(cr);
  }
  return {fx0, fx1, fy0, fy1};
}

// The colour bar of `levels` bands up to `max_speed`, the scale arrow and the groups' legend.
void draw_legend(const Canvas& canvas, const SectionFigure& f, double max_speed, double bx,
                 double by0, double by1, double pixels_per_speed, double longest, bool groups) {
  cairo_t* cr = canvas.cr();
  for (int k = 0; k < f.levels; ++k) {
    const auto c = speed_colour((k + 0.5) / f.levels);
    cairo_set_source_rgb(cr, c[0], c[1], c[2]);
    const double y1 = by1 - (by1 - by0) * k / f.levels, y0 = by1 - (by1 - by0) * (k + 1) / f.levels;
    cairo_rectangle(cr, bx, y0, 26, y1 - y0 + 0.5);
    cairo_fill(cr);
  }
  cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
  canvas.text(bx, by0 - 22, "speed (m/s)", 14, 0.0, 0.5);
  // About five labels, the top (the maximum) always among them.
  const int step = std::max(1, f.levels / 5);
  for (int k = f.levels; k >= 0; k -= step) {
    const double y = by1 - (by1 - by0) * k / f.levels;
    canvas.text(bx + 34, y, fmt::format("{:.3g}", max_speed * k / f.levels), 13, 0.0, 0.5);
  }
  if (longest > 0.0) {
    const double reference = round_down(longest), y = by1 + 45;
    cairo_set_line_width(cr, 1.5);
    arrow_shape(cr, bx, y, bx + reference * pixels_per_speed, y, 8.0);
    canvas.text(bx, y + 14, fmt::format("{:g} m/s in plane", reference), 13, 0.0, 0.0);
  }
  if (groups && !f.groups.empty()) group_legend(canvas, f.groups, bx, by1 + 100);
}

void write_caption(const Canvas& canvas, const std::vector<std::string>& caption, double left,
                   int height) {
  double cy = height - 18.0 * static_cast<double>(caption.size()) - 22;
  cairo_set_source_rgb(canvas.cr(), 0.15, 0.15, 0.15);
  for (const std::string& line : caption) {
    canvas.text(left, cy, line, 15, 0.0, 0.5);
    cy += 20;
  }
}

}  // namespace

void write_section_figure(const SectionFigure& f, const std::filesystem::path& png,
                          const std::filesystem::path& svg, int width, int height) {
  if (f.outline.empty()) fail("{}: the section has no outline to draw", png.string());
  const Extent e = bounds(f);
  const std::vector<std::string> caption = lines_of(f.caption);
  // The page's width follows the section's aspect, so a tall slit does not float in white.
  if (width <= 0) {
    const double plot = height - 140.0 - 22.0 * static_cast<double>(caption.size());
    width = static_cast<int>(std::clamp(plot * (e[1] - e[0]) / (e[3] - e[2]), 360.0, 1100.0)) + 300;
    width = std::max(width, 900);
  }
  Canvas canvas(width, height);
  const double left = 80, right = width - 200, top = 70,
               bottom = height - 70 - 22.0 * static_cast<double>(caption.size());
  const double scale = std::min((right - left) / (e[1] - e[0]), (bottom - top) / (e[3] - e[2]));
  // Secondary velocity: the longest arrow spans 0.9 grid spacings.
  const double longest = longest_arrow(f);
  const double pixels_per_speed = longest > 0.0 ? 0.9 * f.arrow_spacing * scale / longest : 0.0;
  cairo_set_source_rgb(canvas.cr(), 0.1, 0.1, 0.1);
  canvas.text(width / 2.0, 30, f.title, 22, 0.5, 0.5);
  draw_panel(canvas, f, e, left, top, right, bottom, scale, pixels_per_speed, true);
  draw_legend(canvas, f, f.max_speed, width - 170, top + 30, std::min(bottom, top + 500.0),
              pixels_per_speed, longest, !f.crossings.empty());
  write_caption(canvas, caption, left, height);
  canvas.write_png(png);
  if (!svg.empty()) canvas.write_svg(svg);
}

void write_section_grid(const std::vector<SectionFigure>& panels, const std::string& title,
                        const std::string& caption_text, const std::filesystem::path& png,
                        const std::filesystem::path& svg) {
  if (panels.empty()) fail("{}: no sections to draw", png.string());
  // One scale for all: the largest extent of any panel, each centred on its own section.
  double span_u = 0.0, span_v = 0.0, longest = 0.0, spacing = INFINITY;
  for (const SectionFigure& f : panels) {
    if (f.outline.empty()) fail("{}: a section has no outline to draw", png.string());
    const Extent e = bounds(f);
    span_u = std::max(span_u, e[1] - e[0]);
    span_v = std::max(span_v, e[3] - e[2]);
    longest = std::max(longest, longest_arrow(f));
    spacing = std::min(spacing, f.arrow_spacing);
  }
  const std::vector<std::string> caption = lines_of(caption_text);
  const int height = 900, n = static_cast<int>(panels.size());
  const double panel_height = height - 160.0 - 22.0 * static_cast<double>(caption.size());
  const double panel_width = std::clamp(panel_height * span_u / span_v, 200.0, 700.0) + 90.0;
  const int width = std::max(900, static_cast<int>(n * panel_width + 320.0));
  const double scale = std::min((panel_width - 90.0) / span_u, panel_height / span_v);
  const double pixels_per_speed = longest > 0.0 ? 0.9 * spacing * scale / longest : 0.0;
  Canvas canvas(width, height);
  cairo_set_source_rgb(canvas.cr(), 0.1, 0.1, 0.1);
  canvas.text(width / 2.0, 30, title, 22, 0.5, 0.5);
  bool crossings = false;
  for (int k = 0; k < n; ++k) {
    const SectionFigure& f = panels[static_cast<std::size_t>(k)];
    const Extent own = bounds(f);
    const double cu = 0.5 * (own[0] + own[1]), cv = 0.5 * (own[2] + own[3]);
    const Extent e{cu - 0.5 * span_u, cu + 0.5 * span_u, cv - 0.5 * span_v, cv + 0.5 * span_v};
    const double left = 70.0 + k * panel_width, top = 90.0;
    const auto frame = draw_panel(canvas, f, e, left, top, left + panel_width - 90.0,
                                  top + panel_height, scale, pixels_per_speed, false);
    cairo_set_source_rgb(canvas.cr(), 0.1, 0.1, 0.1);
    canvas.text(0.5 * (frame[0] + frame[1]), top - 22, f.title, 16, 0.5, 0.5);
    crossings = crossings || !f.crossings.empty();
  }
  draw_legend(canvas, panels.front(), panels.front().max_speed, width - 200, 120,
              std::min(90.0 + panel_height, 620.0), pixels_per_speed, longest, crossings);
  write_caption(canvas, caption, 70, height);
  canvas.write_png(png);
  if (!svg.empty()) canvas.write_svg(svg);
}

}  // namespace naris::figures
