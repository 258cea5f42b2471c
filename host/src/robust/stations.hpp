#pragma once
// Where along a seam the cross-sections are fitted. The curve a seam is traced along starts
// where its node path (or the previous pass's roots) starts, and one crease node more or less
// at an end - a micrometre of depth, the OpenCL backend's rounding - moves every station along
// the seam. A section's slab (+-1.5 mm) then holds other points, and on a noisy scan its root
// moves by tenths of a millimetre, or its fit passes where it failed. The stations are
// therefore anchored to the cloud's frame, not to the curve's start.

#include <groovetrace/robust.hpp>

namespace groovetrace {

/// Resamples `dense` (a curve from smooth_curve, sampled much finer than `spacing`) at stations
/// about `spacing` (m) apart whose places are fixed by the frame: wherever the curve crosses a
/// plane normal to an axis at a multiple of 20 `spacing` (at over 30 degrees), and from there
/// every `spacing` both ways up to half-way to the next such crossing. An open curve keeps its
/// ends as stations where they lie over half a spacing from the nearest one. Tangents and
/// corners are the dense curve's.
SeamCurve anchored_stations(const SeamCurve& dense, double spacing);

}  // namespace groovetrace
