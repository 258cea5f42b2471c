#pragma once
// The cpu backend's crease measure (FeatureBackend::crease), the reference of kernels/crease.cl.

#include <groovetrace/features.hpp>

namespace groovetrace {

/// FeatureBackend::crease on the CPU: the quantile selected exactly. OpenMP over grid cells.
CreaseMeasure crease_cpu(const Cloud& cloud, const CreaseParams& params);

}  // namespace groovetrace
