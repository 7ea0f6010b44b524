#pragma once
// The camera front end's plain-struct configuration from a PosedConfig (core/ never sees YAML):
// the cameras' intrinsics and extrinsics and the `frontend` section. Used by the pipeline,
// `posectl bench frontend` and `posectl inspect frontend`, so all run the same front end.

#include <string>

#include "core/fusion/camera_factors.hpp"
#include "core/fusion/camera_front_end.hpp"
#include "daemon/config/posed_config.hpp"

namespace posed::pipeline {

/// The front end for a rig with the cameras present. `in_stamp_order`: the fusion stage merges
/// by stamp (replays), so no frame can arrive behind the IMU. The mode falls back to what the
/// cameras allow (thermal without a visible camera, visible without a thermal one) and `note`
/// says so; empty when the configured mode runs.
fusion::CameraFrontEndConfig camera_front_end_config(const config::PosedConfig& config,
                                                     bool has_visible, bool has_thermal,
                                                     bool in_stamp_order, std::string& note);

/// frontend.mode for two streams: the visible and thermal runs each feed the estimate.
inline constexpr const char* kTwoStreams = "visible+thermal";

/// The camera back end for the front end `cameras` builds: which streams enter the window
/// (estimator.camera_coupling, frontend.mode), their cameras in base_link, the noise, quality
/// weighting and gating of the estimator section.
fusion::CameraFactorsConfig camera_factors_config(const config::PosedConfig& config,
                                                  const fusion::CameraFrontEndConfig& cameras);

/// `frontend.mode` as the front end's (primary) mode; false for "off". visible+thermal: visible.
bool frontend_mode(const std::string& name, vision::FrontendMode& mode);

/// A camera section as the front end's camera model.
vision::PinholeCamera pinhole(const config::CameraSection& camera);

}  // namespace posed::pipeline
