#include "picture/overview.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

#include "picture/font.hpp"
#include "picture/png.hpp"
#include "picture/surface.hpp"
#include "picture/view.hpp"

namespace groovetrace::picture {
namespace {

constexpr Rgb kHalo{12, 12, 14};       // under lines and text, so they read on any shade
constexpr Rgb kTick{255, 255, 255};    // tool-axis ticks and the scale bar
constexpr Rgb kBar{36, 38, 44};        // the caption bar
constexpr Rgb kText{235, 235, 235};    // caption text
constexpr double kTickLength = 0.005;  // m along the tool z axis, from the torch side
constexpr int kGridBaseline = 2;       // grid pixels between the points of a normal

// Sizes from the picture's size, so that a thumbnail reads like the full picture.
struct Style {
  double unit = 1;  // pixels: the width of a thin line
  int font = 1;     // font scale of the caption
};

Style style_for(const Raster& picture) {
  Style s;
  s.unit = std::max(1.0, std::max(picture.width(), picture.height()) / 400.0);
  s.font = std::clamp(static_cast<int>(std::lround(picture.width() / 320.0)), 1, 3);
  return s;
}

std::string one_decimal(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

// Text with a dark outline one font pixel wide, readable over the scan.
void outlined_text(Raster& image, int x, int y, const std::string& text, int scale, Rgb c) {
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx)
      draw_text(image, x + dx * scale, y + dy * scale, text, scale, kHalo);
  }
  draw_text(image, x, y, text, scale, c);
}

// Waypoint discs shrink where waypoints crowd, so that each stays visible (pixels).
double disc_radius(const std::vector<Eigen::Vector2d>& px, const Style& st) {
  std::vector<double> gaps;
  for (std::size_t i = 1; i < px.size(); ++i) gaps.push_back((px[i] - px[i - 1]).norm());
  double r = 1.8 * st.unit;
  if (!gaps.empty()) {
    auto mid = gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2);
    std::nth_element(gaps.begin(), mid, gaps.end());
    if (std::isfinite(*mid)) r = std::min(r, 0.4 * *mid);
  }
  return std::max(r, 1.2);
}

// Tool z ticks from the torch side (kTickLength before the waypoint) to the waypoint, at
// waypoints at least 10 line widths apart in the picture.
void draw_ticks(Raster& image, const View& view, const Trajectory& t, const Eigen::Isometry3d& T,
                const std::vector<Eigen::Vector2d>& px, const Style& st) {
  Eigen::Vector2d last = Eigen::Vector2d::Constant(INFINITY);
  for (std::size_t i = 0; i < px.size(); ++i) {
    if (!px[i].allFinite() || (px[i] - last).norm() < 10 * st.unit) continue;
    last = px[i];
    const Waypoint& w = t.waypoints[i];
    const Eigen::Vector3d z_cloud = T.linear() * (w.orientation * Eigen::Vector3d::UnitZ());
    const Eigen::Vector2d torch = view.project(T * w.position - kTickLength * z_cloud);
    image.line(torch, px[i], st.unit + 2, kHalo);
    image.line(torch, px[i], st.unit, kTick);
  }
}

// An arrowhead at the last waypoint, pointing along the travel.
void draw_arrowhead(Raster& image, const std::vector<Eigen::Vector2d>& px, Rgb c, double len) {
  const Eigen::Vector2d tip = px.back();
  for (std::size_t i = px.size() - 1; i-- > 0;) {
    const Eigen::Vector2d d = tip - px[i];
    if (!(d.norm() >= len)) continue;  // a stable direction, not the last step's noise
    const Eigen::Vector2d u = d.normalized(), n(-u.y(), u.x());
    for (double side : {-1.0, 1.0}) {
      image.line(tip, tip - len * u + side * 0.6 * len * n, len / 3 + 2, kHalo);
      image.line(tip, tip - len * u + side * 0.6 * len * n, len / 3, c);
    }
    return;
  }
}

// One seam: the path, its waypoints, ticks, a larger disc at the start and an arrowhead at
// the end (the direction of travel).
void draw_seam(Raster& image, const View& view, const Trajectory& t, const Eigen::Isometry3d& T,
               Rgb c, const Style& st) {
  std::vector<Eigen::Vector2d> px;
  for (const Waypoint& w : t.waypoints) px.push_back(view.project(T * w.position));
  if (px.empty()) return;
  const double width = 1.2 * st.unit;
  for (std::size_t i = 1; i < px.size(); ++i) image.line(px[i - 1], px[i], width + 1, kHalo);
  for (std::size_t i = 1; i < px.size(); ++i) image.line(px[i - 1], px[i], width, c);
  draw_ticks(image, view, t, T, px, st);
  const double r = disc_radius(px, st);
  for (const Eigen::Vector2d& p : px) {
    image.disc(p, r + 1, kHalo);
    image.disc(p, r, c);
  }
  image.disc(px.front(), 3 * st.unit + 1, kHalo);
  image.disc(px.front(), 3 * st.unit, c);
  if (px.size() > 1) draw_arrowhead(image, px, c, 6 * st.unit);
}

// The seam's number beside its start, when there are several.
void draw_label(Raster& image, const View& view, const Trajectory& t, const Eigen::Isometry3d& T,
                const std::string& text, Rgb c, const Style& st) {
  if (t.waypoints.empty()) return;
  const Eigen::Vector2d p = view.project(T * t.waypoints.front().position);
  if (!p.allFinite()) return;
  const int gap = static_cast<int>(std::lround(4 * st.unit));
  outlined_text(image, static_cast<int>(p.x()) + gap, static_cast<int>(p.y()) - gap - 7 * st.font,
                text, st.font, c);
}

// Where the scale bar's pixels per metre hold: the best seam's middle waypoint, else the
// scan's centroid (a pinhole picture's scale changes with depth).
Eigen::Vector3d reference_point(const OverviewInput& in) {
  for (const Trajectory& t : in.trajectories) {
    if (!t.waypoints.empty())
      return in.T_cloud_trajectory * t.waypoints[t.waypoints.size() / 2].position;
  }
  return valid_centroid(in.cloud);
}

// A bar of a round length (1, 2 or 5 times a power of ten, mm) at the bottom right, at most
// a fifth of the picture wide.
void draw_scale_bar(Raster& image, double px_per_m, const Style& st) {
  if (!(px_per_m > 0) || !std::isfinite(px_per_m)) return;
  double mm = 0;
  for (double decade = 0.1; decade < 1e5; decade *= 10) {
    for (double f : {1.0, 2.0, 5.0}) {
      if (f * decade * 1e-3 * px_per_m <= 0.2 * image.width()) mm = f * decade;
    }
  }
  if (mm == 0) return;
  const std::string label = (mm < 1 ? one_decimal(mm) : std::to_string(std::lround(mm))) + " mm";
  const int s = st.font, pad = 3 * s, len = static_cast<int>(std::lround(mm * 1e-3 * px_per_m));
  const int box_w = text_width(label, s) + len + 3 * pad, box_h = 7 * s + 2 * pad;
  const int x0 = image.width() - box_w - pad, y0 = image.height() - box_h - pad;
  for (int y = y0; y < y0 + box_h; ++y) {
    for (int x = x0; x < x0 + box_w; ++x) image.blend(x, y, kHalo, 0.6);
  }
  draw_text(image, x0 + pad, y0 + pad, label, s, kText);
  const double bx = x0 + 2 * pad + text_width(label, s), by = y0 + box_h / 2.0;
  image.line({bx, by}, {bx + len, by}, st.unit, kTick);
  for (double x : {bx, bx + len}) image.line({x, by - 2 * s}, {x, by + 2 * s}, st.unit, kTick);
}

// `text` cut from the front (with "...") to fit `width` pixels at `scale`: the status at the
// end matters most.
std::string fit_text(const std::string& text, int scale, int width) {
  if (text_width(text, scale) <= width) return text;
  const int chars = std::max(0, (width + scale) / (kGlyphAdvance * scale) - 3);
  return "..." + text.substr(text.size() - std::min<std::size_t>(text.size(), chars));
}

// The picture over a caption bar one line of text high.
Raster with_caption(const Raster& picture, const std::string& text, const Style& st) {
  int scale = st.font;
  while (scale > 1 && text_width(text, scale) > picture.width() - 6 * scale) --scale;
  const int pad = 3 * scale;
  Raster out(picture.width(), picture.height() + kGlyphHeight * scale + 2 * pad, kBar);
  out.paste(picture, 0, 0);
  draw_text(out, pad, picture.height() + pad, fit_text(text, scale, picture.width() - 2 * pad),
            scale, kText);
  return out;
}

}  // namespace

Rgb seam_colour(std::size_t k) {
  static constexpr std::array<Rgb, 6> kSeams = {{{0, 200, 255},
                                                 {255, 60, 200},
                                                 {120, 230, 40},
                                                 {255, 235, 60},
                                                 {160, 120, 255},
                                                 {255, 255, 255}}};
  return kSeams[k % kSeams.size()];
}

std::string caption_line(const std::string& file, const std::string& method,
                         const std::vector<Trajectory>& trajectories, const std::string& status) {
  const std::size_t n = trajectories.size();
  std::string text =
      file + "  " + method + "  " + std::to_string(n) + (n == 1 ? " seam" : " seams");
  double total = 0;
  std::string lengths;
  for (const Trajectory& t : trajectories) {
    lengths += (lengths.empty() ? "" : " + ") + one_decimal(t.length * 1000);
    total += t.length * 1000;
  }
  // More than three lengths would crowd the line: their sum instead.
  if (n > 3) lengths = one_decimal(total) + " total";
  if (n > 0) text += "  " + lengths + " mm";
  return text + "  " + status;
}

Raster render_overview(const OverviewInput& in, int max_side) {
  View view = pinhole_view(in.cloud, max_side);
  Raster picture;
  if (view.width > 0) {
    // Shaded at the frame's own size, then resampled: the normals need the grid neighbours.
    picture =
        resample(shade(grid_surface(in.cloud, in.groove), kGridBaseline), view.width, view.height);
  } else {
    view = top_view(in.cloud, in.viewpoint.value_or(in.cloud.viewpoint), max_side);
    const int side = splat_side(in.cloud, view);
    picture = shade(splat_surface(in.cloud, in.groove, view, side), std::max(kGridBaseline, side));
  }
  const Style st = style_for(picture);
  const auto& T = in.T_cloud_trajectory;
  for (std::size_t k = 0; k < in.trajectories.size(); ++k) {
    draw_seam(picture, view, in.trajectories[k], T, seam_colour(k), st);
  }
  for (std::size_t k = 0; k < in.trajectories.size() && in.trajectories.size() > 1; ++k) {
    draw_label(picture, view, in.trajectories[k], T, std::to_string(k + 1), seam_colour(k), st);
  }
  draw_scale_bar(picture, view.pixels_per_metre(reference_point(in)), st);
  return with_caption(picture, in.caption, st);
}

std::string overview_png(const OverviewInput& input, int max_side) {
  return encode_png(render_overview(input, max_side));
}

}  // namespace groovetrace::picture
