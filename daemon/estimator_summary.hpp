#pragma once
// The exit summary's lines about the cameras in the estimate: which modalities, each camera
// stream's factors, weight and gate, and seed 001's pose selection.

#include "core/estimator/fusion_core.hpp"

namespace posed {

/// Prints nothing when no camera stream fed the estimate.
void print_visual_summary(const FusionFigures& figures);

}  // namespace posed
