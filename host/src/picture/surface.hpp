#pragma once
// The shaded background of the overview: a grid of surface points in the view frame (x right,
// y down, z away from the viewer; metres), lit from the viewer's upper left so that a groove's
// two walls read as one light and one dark band, with the groove points tinted.

#include <Eigen/Core>
#include <cstdint>
#include <groovetrace/cloud.hpp>
#include <vector>

#include "picture/raster.hpp"
#include "picture/view.hpp"

namespace groovetrace::picture {

constexpr Rgb kNothing{22, 24, 30};      ///< where nothing was measured
constexpr Rgb kGrooveTint{255, 130, 0};  ///< groove points, mixed over their shading
constexpr double kGrooveAlpha = 0.65;

/// Surface points on a pixel grid, with their groove labels.
struct Surface {
  int width = 0, height = 0;
  std::vector<Eigen::Vector3f> p_view;  ///< per pixel, row-major, m, view frame; NaN = empty
  std::vector<std::uint8_t> groove;     ///< per pixel: 1 = groove point
};

/// An organized frame as it is: pixel (col, row) holds point row * width + col. Its camera
/// frame is the view frame of a pinhole view. `groove` is per point (1 = groove); one of
/// another size counts as none.
Surface grid_surface(const Cloud& cloud, const std::vector<std::uint8_t>& groove);

/// The valid points splatted into a top view's picture, the nearest to the viewer winning a
/// pixel; each point covers a square of `side` pixels (splat_side), and pixels with at least
/// five filled neighbours of eight are filled with their mean.
Surface splat_surface(const Cloud& cloud, const std::vector<std::uint8_t>& groove, const View& view,
                      int side);

/// The square (pixels) a point must cover for the valid points to close into a surface in
/// `view`: their mean spacing in pixels, from their density over the occupied area, 1 to 8.
int splat_side(const Cloud& cloud, const View& view);

/// Grey Lambert shading from the normals of the surface box-smoothed over `baseline` pixels,
/// taken between the neighbours `baseline` pixels away (so that depth noise does not speckle
/// it), darker the lower a point lies below the others (its height above the plane fitted to
/// all); groove pixels tinted, empty ones kNothing.
Raster shade(const Surface& surface, int baseline);

/// `image` at width x height: each pixel the mean of the pixels under it (or the nearest
/// when enlarging).
Raster resample(const Raster& image, int width, int height);

}  // namespace groovetrace::picture
