#pragma once
// The estimators' plain-struct configuration from a PosedConfig (core/ never sees YAML): used by
// the pipeline, `posectl bench lio` and the tests, so all three run the same estimator.

#include "core/estimator/lio_estimator.hpp"
#include "core/estimator/strapdown.hpp"
#include "core/mapping/localiser.hpp"
#include "core/mapping/loop_closer.hpp"
#include "daemon/config/posed_config.hpp"

namespace posed::pipeline {

estimator::LioConfig lio_config(const config::PosedConfig& config);
StrapdownConfig strapdown_config(const config::PosedConfig& config);
/// The mapping stage's loop closer: mapping.* and the estimator's keyframe spacing.
mapping::LoopClosureConfig loop_closure_config(const config::PosedConfig& config);
/// The mapping stage's localiser on a prior map: mapping.localise_every_m, lost_after_m and the
/// registration's tests.
mapping::LocalisationConfig localisation_config(const config::PosedConfig& config);
/// mapping.initial_* as base_link in the map.
Eigen::Isometry3d initial_pose(const config::MappingSection& m);

/// A 4x4 row-major config transform as an isometry.
Eigen::Isometry3d to_isometry(const config::Transform4& T);

}  // namespace posed::pipeline
