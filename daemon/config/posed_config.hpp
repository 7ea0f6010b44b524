#pragma once
// posed's configuration as plain structs (DESIGN.md, Configuration). Every field is described,
// with its unit, range and default, in exactly one place: the schema table in config_schema.cpp.
// The values here are only what a default-constructed struct holds before the schema's defaults
// are applied by default_config().

#include <array>
#include <cstdint>
#include <string>

#include "drivers/imu/can_imu_mapping.hpp"

namespace posed::config {

/// A 4x4 homogeneous transform, row-major: T_a_b maps points from frame b into frame a.
using Transform4 = std::array<double, 16>;
/// A 3x3 rotation, row-major.
using Rotation3 = std::array<double, 9>;

/// DDS Security (docs/security.md): either an SROS2 enclave directory or the six files; none of
/// them: plain DDS.
struct DdsSecuritySection {
  std::string enclave;  ///< SROS2 enclave directory (…/enclaves/posed) holding the six files
  std::string identity_ca;
  std::string certificate;
  std::string private_key;
  std::string permissions_ca;
  std::string governance;
  std::string permissions;
};

struct DdsSection {
  int domain_id = 0;
  std::string map_frame;
  std::string base_frame;
  std::string odom_frame;     ///< REP-105's odom frame (rt/tf: map -> odom -> base_link)
  std::string lidar_frame;    ///< rt/tf_static child of base_link: T_imu_lidar
  std::string camera_frame;   ///< rt/tf_static child of base_link: T_imu_cam
  std::string thermal_frame;  ///< rt/tf_static child of base_link: T_imu_cam * T_cam_thermal
  /// Cyclone DDS XML file; empty = CYCLONEDDS_URI or Cyclone's built-in default
  std::string cyclonedds_config;
  /// DDS topic of the initial pose (RViz's /initialpose is rt/initialpose); empty: none read
  std::string initialpose_topic;
  DdsSecuritySection security;
};

struct PublishSection {
  int odom_decimation = 1;  ///< publish every Nth propagated state on rt/posed/odom
  /// odometry propagated on the IMU stage's thread from the newest optimised state, never
  /// waiting for scan matching, cameras or the window (false: by the back end, late by them)
  bool odom_decoupled = true;
  double odom_blend_s = 0.1;    ///< a correction to odometry is spread over this long [s]
  double pose_rate_hz = 10.0;   ///< rt/posed/pose rate while the estimator is strapdown [Hz]
  double status_rate_hz = 1.0;  ///< rt/posed/status rate [Hz]
  /// rt/tf (map -> odom -> base_link, with each pose) and rt/tf_static (base_link -> sensors)
  bool tf = true;
  double tf_max_rate_hz = 0;  ///< at most this many rt/tf messages per second; 0: every pose [Hz]
  bool path = true;           ///< rt/posed/path
  double path_rate_hz = 1.0;  ///< rt/posed/path messages per second [Hz]
  double path_min_step_m = 0.1;  ///< a pose joins the path after the base moved this far [m]
  int path_max_poses = 10000;    ///< past this, every other old pose is dropped [count]
  bool diagnostics = true;       ///< rt/diagnostics, with each status
  bool cloud = true;             ///< rt/posed/cloud: each matched scan, deskewed
  double cloud_max_rate_hz = 0;  ///< at most this many clouds per second; 0: every scan [Hz]
  bool map = true;               ///< rt/posed/map: the local map, transient-local
  double map_rate_hz = 0.2;      ///< rt/posed/map messages per second [Hz]
  bool image = true;             ///< rt/posed/image/compressed: the front end's tracked image
  double image_rate_hz = 5;      ///< at most this many images per second [Hz]
};

struct ImuSection {
  std::string source;         ///< synthetic | serial | can
  double rate_hz = 150.0;     ///< nominal sample rate [Hz]
  std::string serial_device;  ///< path or /dev/serial/by-id/... of the A9
  int serial_baud = 921600;   ///< [baud]
  std::string can_interface;  ///< SocketCAN interface of a CAN IMU (can0, vcan0)
  /// Which CAN frame carries which IMU field, at which byte, type and scale: read by a live CAN
  /// IMU and by a replay of recorded or imported CAN frames. No fields = no mapping.
  drivers::can::CanImuMapping can_mapping;
  Rotation3 R_imu_sensor{};          ///< mounting rotation, sensor axes into the IMU frame
  double gyro_noise_density = 0.0;   ///< [rad/s/sqrt(Hz)]
  double gyro_random_walk = 0.0;     ///< [rad/s^2/sqrt(Hz)]
  double accel_noise_density = 0.0;  ///< [m/s^2/sqrt(Hz)]
  double accel_random_walk = 0.0;    ///< [m/s^3/sqrt(Hz)]
  double gravity_mps2 = 9.805;       ///< local gravity magnitude [m/s^2]
  std::string clock_kind;            ///< counter_us_32bit | us_past_hour | hardware_ns | none
  double clock_latency_s = 0;        ///< minimum transport latency, device stamp to arrival [s]
};

struct SyntheticImuSection {
  double rate_hz = 200.0;            ///< [Hz]
  double radius_m = 5.0;             ///< circle radius [m]
  double speed_mps = 1.0;            ///< cruise speed along the circle [m/s]
  double static_s = 2.0;             ///< standing still at start, for gravity alignment [s]
  double ramp_s = 3.0;               ///< time to reach cruise speed [s]
  double gyro_noise_density = 0.0;   ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 0.0;  ///< [m/s^2/sqrt(Hz)]
  int seed = 1;                      ///< noise seed
  double hang_after_s = 0;           ///< fault injection: the fake device hangs after this long [s]
};

struct LidarSection {
  bool enabled = false;
  std::string source;          ///< udp (the sensor) | pcap (a capture played as if live)
  std::string pcap_file;       ///< capture for source pcap
  double pcap_speed = 1.0;     ///< 1 = original timing, N = N times faster
  double cut_azimuth_deg = 0;  ///< where one scan ends and the next begins [deg]
  std::string address;         ///< sensor IPv4 address; datagrams from elsewhere are dropped
  int data_port = 2368;
  int position_port = 8308;
  std::string calibration;  ///< VeloView XML / ros-drivers YAML / velodyne_decoder YAML
  double min_range_m = 0.5;
  double max_range_m = 120.0;
  double rpm = 600.0;
  std::string clock_kind;      ///< how the device stamps packets
  double clock_latency_s = 0;  ///< minimum transport latency [s]
};

struct CameraSection {
  bool enabled = false;
  std::string device;                         ///< V4L2 path, /dev/v4l/by-id/..., or serial
  std::string source;                         ///< v4l2 | aravis
  std::string format;                         ///< wire pixel format (yuyv, y8, y16, mjpeg, ...)
  std::string intrinsics_source = "factory";  ///< factory (D435i HW monitor) | config
  int width = 0;                              ///< [px]
  int height = 0;                             ///< [px]
  double rate_hz = 0;                         ///< [Hz]
  double fx = 0, fy = 0, cx = 0, cy = 0;      ///< pinhole intrinsics [px]
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0;      ///< radial-tangential distortion
  double latency_s = 0;    ///< least host arrival minus exposure midpoint of a frame [s]
  std::string clock_kind;  ///< hardware_ns (D435i metadata) | none (UVC thermal)
};

/// The D435i's depth node (Z16 from the left IR imager of its stereo pair): read like a camera
/// (the CameraSection fields; fx..cy are the rectified depth image's, no distortion), it gives
/// the camera features depth where the lidar gives none.
struct DepthCameraSection : CameraSection {
  double baseline_m = 0;    ///< stereo baseline, left to right IR imager [m]
  double depth_unit_m = 0;  ///< metres per Z16 count [m]
  double min_range_m = 0;   ///< nearer: no stereo match, reported 0 [m]
  double max_range_m = 0;   ///< farther: reported 0 [m]
  /// features the lidar gives no depth take the depth image's
  bool feature_depth = false;
  int feature_stride_px = 4;           ///< one depth point per stride x stride pixels [px]
  double feature_min_range_m = 0.3;    ///< nearer depths are not used [m]
  double feature_max_range_m = 4.0;    ///< further depths are not used [m]
  double feature_max_span_m = 0.3;     ///< a feature's 3 depth points spanning more: none [m]
  double feature_max_offset_s = 0.04;  ///< depth image to frame stamp, at most [s]
};

/// The D435i's own IMU (BMI055 over IIO HID): the A9's backup. When the A9 falls silent the
/// estimate and rt/posed/odom carry on with it, and go back to the A9 when it returns.
struct RealsenseImuSection {
  bool enabled = false;            ///< read it live (RealsenseImuSource)
  bool failover = true;            ///< use it while the A9 is silent (live, or a recording's)
  double failover_after_s = 0.05;  ///< A9 silence before its samples are replaced [s]
  double accel_rate_hz = 250;      ///< [Hz]
  double gyro_rate_hz = 200;       ///< [Hz]
  double clock_latency_s = 0;      ///< minimum transport latency, device stamp to arrival [s]
  // The estimator weighs its samples with these while it stands in for the A9.
  double gyro_noise_density = 0;   ///< [rad/s/sqrt(Hz)]
  double accel_noise_density = 0;  ///< [m/s^2/sqrt(Hz)]
  double gyro_random_walk = 0;     ///< [rad/s^2/sqrt(Hz)]
  double accel_random_walk = 0;    ///< [m/s^3/sqrt(Hz)]
  /// 1 sigma per axis of its biases less the A9's: the step the bias state may take at a switch
  double gyro_bias_offset_radps = 0;                ///< [rad/s]
  double accel_bias_offset_mps2 = 0;                ///< [m/s^2]
  std::string sysfs_root = "/sys/bus/iio/devices";  ///< where the IIO devices are listed
  std::string dev_dir = "/dev";                     ///< where their character devices are
};

struct SyncSection {
  double pairing_tolerance_s = 0.02;  ///< visible/thermal frames further apart are not paired [s]
};

struct ExtrinsicsSection {
  Transform4 T_imu_lidar{};
  Transform4 T_imu_cam{};
  Transform4 T_cam_thermal{};
  Transform4 T_cam_depth{};
  Transform4 T_depth_rsimu{};
};

struct FrontendSection {
  std::string mode = "visible";  ///< off | visible | thermal | fused | visible+thermal
  bool enhance_visible = true;
  double gamma_target_mean = 0.5;                 ///< [0..1]
  double clahe_clip_limit = 2.0;                  ///< [x uniform bin]
  std::string thermal_registration = "infinity";  ///< infinity | plane | fov_crop | lidar_depth
  double thermal_plane_depth_m = 10;              ///< [m]
  int thermal_depth_grid_cols = 40;               ///< lidar_depth registration grid [cells]
  int thermal_depth_grid_rows = 30;               ///< [cells]
  bool rotation_compensation = true;
  bool thermal_nuc = false;         ///< scene-based non-uniformity correction of the thermal
  double thermal_nuc_frames = 100;  ///< [frames] the NUC's offsets average over
  /// the front end on a thread of its own beside the lidar front end (with the cameras in the
  /// window); false: on the fusion thread. The estimate is the same either way.
  bool own_thread = true;
  std::string wavelet = "haar";              ///< haar | legall53 | cdf97
  bool fusion_noise_weighted = true;         ///< false: seed 000's eq. (8) as published
  bool fusion_denoise = true;                ///< noise-adaptive pre-smoothing of the fusion inputs
  double fusion_denoise_target_sigma = 2.0;  ///< [grey]
  int max_features = 300;
  double min_feature_distance_px = 20;  ///< [px]
  double ransac_threshold_px = 4;       ///< [px]
  int ransac_max_iterations = 200;      ///< RANSAC's draws at most [1]
  double forward_backward_px = 0.5;     ///< KLT round-trip error allowed [px]
  int klt_window_px = 15;               ///< KLT window side [px]
  int klt_pyramid_levels = 3;           ///< KLT pyramid levels above the image [1]
  bool lines = false;
  double depth_window_s = 1;  ///< [s]
  int depth_points_per_scan = 20000;
  double depth_max_span_m = 2;       ///< [m]
  double corner_noise_factor = 4.0;  ///< new corners above this x the median corner score
  double quality_lambda_n = 0.1;     ///< seed 002's λn: scale of ω [1/grey]
  double quality_lambda_g = 10.0;    ///< seed 002's λg: weight of the gradient metric in ω [grey]
};

struct EstimatorSection {
  double init_static_s = 1.0;           ///< IMU averaged for the gravity alignment [s]
  double init_max_gyro_radps = 0.05;    ///< above this the rig is not static [rad/s]
  int window_size = 10;                 ///< states in the fixed-lag window [1]
  bool estimate_gravity_tilt = true;    ///< the map frame's tilt as a window block
  double gravity_tilt_prior_deg = 1.0;  ///< its prior at a (re)start, 1 sigma per axis [deg]
  /// held until the heading has spanned this much [deg]
  double gravity_tilt_release_heading_deg = 45.0;
  int solver_iterations = 8;                 ///< Levenberg-Marquardt iterations per scan [1]
  std::string vehicle_motion = "off";        ///< off | always | blind
  double vehicle_min_yaw_rate_dps = 0;       ///< blind: only while turning this fast [deg/s]
  double vehicle_lateral_sigma_mps = 0.05;   ///< [m/s]
  double vehicle_vertical_sigma_mps = 0.05;  ///< [m/s]
  double vehicle_centre_x_m = 0;             ///< the no-slip point in base_link [m]
  double vehicle_centre_y_m = 0;             ///< [m]
  double vehicle_centre_z_m = 0;             ///< [m]
  double max_speed_mps = 40;                 ///< faster means diverged [m/s]
  double max_gyro_bias_radps = 0.3;          ///< larger means diverged [rad/s]
  double max_accel_bias_mps2 = 2.0;          ///< larger means diverged [m/s^2]
  double max_match_jump_m = 1.0;     ///< a scan match further from the IMU prediction is refused
  double max_match_jump_deg = 11.5;  ///< [deg]
  bool degeneracy_handling = true;   ///< remap degenerate directions to the IMU prediction
  double degeneracy_translation_threshold = 10;  ///< point constraints [1]
  double degeneracy_rotation_threshold_m2 = 20;  ///< squared lever arms [m^2]
  double degenerate_information_scale = 0.01;    ///< what a scan says along them, weighed [-]
  double plane_voxel_m = 0.4;                    ///< planar features downsampling [m]
  double edge_voxel_m = 0.2;                     ///< edge features downsampling [m]
  double map_radius_m = 120;                     ///< local map kept around the robot [m]
  double map_confirm_s = 0;          ///< a map voxel is matched once scans hit it this long [s]
  double keyframe_distance_m = 1.0;  ///< keyframe spacing [m]
  double keyframe_angle_deg = 11.5;  ///< keyframe spacing [deg]
  std::string camera_coupling = "loose";      ///< loose (between factors) | landmarks | off
  double camera_pixel_sigma_px = 1.0;         ///< Σ_base of a frame-to-frame motion [px]
  bool camera_quality_weighting = true;       ///< Σ = ω Σ_base (seed 002); false: ω = 1
  bool camera_residual_scaling = true;        ///< and by their disagreement with the other stream
  bool camera_thermal_gate_strict = true;     ///< thermal majority off the IMU's guess: no motion
  bool camera_thermal_standby = false;        ///< thermal factors only while visible is gated out
  double camera_min_confidence = 0.05;        ///< a stream below it leaves the estimate [0..1]
  double camera_rejoin_confidence = 0.08;     ///< and returns at or above it [0..1]
  double camera_min_gradient = 0.02;          ///< or below this gradient metric g [0..1]
  double camera_rejoin_gradient = 0.04;       ///< [0..1]
  double camera_floor_translation_m = 0.002;  ///< 1-sigma floor per factor [m]
  /// the same where the lidar is strong (no degenerate scan lately) [m]
  double camera_strong_lidar_floor_translation_m = 0.002;
  /// the strong-lidar floor only once every scan for this long pinned every direction [s]
  double camera_strong_lidar_after_s = 5;
  double camera_floor_rotation_deg = 0.06;    ///< 1-sigma floor per factor [deg]
  int camera_keyframe_states = 5;             ///< states a keyframe anchors motions for [1]
  double camera_landmark_gate_px = 20;        ///< observations further off are not added [px]
  double camera_landmark_outlier_sigma = 15;  ///< landmarks the solve leaves further off go [sigma]
  double camera_landmark_huber_sigma = 3;     ///< Huber threshold of their factors [sigma]
  double camera_still_flow_sigma = 2;         ///< features that hold still are left out [sigma]
  double camera_aperture_max_ratio = 0;  ///< edges' sigma along themselves up to this; 0: off [1]
  double camera_guess_gate_px = 3;       ///< features further from the prediction: out [px]
  double camera_weak_lidar_guess_gate_px = 6;           ///< the same near a degenerate scan [px]
  bool pose_selection = true;                           ///< seed 001's adaptive initial value
  double camera_degeneracy_translation_threshold = 10;  ///< with cameras in the estimate [1]
  double camera_degenerate_information_scale = 0;       ///< with cameras in the estimate [-]
  double camera_lidar_trusted_constraints = 200;  ///< above: a scan's direction is not checked [1]
  double camera_lidar_consistency_sigma = 3;      ///< scan vs cameras disagreement allowed
  double camera_lidar_suspect_window_s = 5;  ///< checked only this long after a degenerate scan [s]
  double camera_blind_weak_lidar_ratio = 0.5;  ///< cameras blind there: weaker than this share of
                                               ///< the scan's best translation, left to the IMU
};

/// One pipeline thread: SCHED_FIFO priority (0 = normal scheduling) and CPU (-1 = any).
struct ThreadSection {
  int priority = 0;
  int cpu = -1;
};

struct ThreadsSection {
  ThreadSection imu_source;
  ThreadSection lidar_source;
  ThreadSection fusion;
  ThreadSection camera_source;
  ThreadSection camera_frontend;  ///< posed-camera: the camera front end (frontend.own_thread)
  ThreadSection publisher;
  /// posed-lidar-hN: helpers of the fusion thread's scan match (0: the fusion thread alone)
  int lidar_helpers = 1;
  ThreadSection lidar_helper;
};

struct QueuesSection {
  int imu_capacity = 1024;    ///< IMU samples between the IMU source and the fusion core
  int scan_capacity = 4;      ///< lidar scans between the lidar source and the fusion core
  int image_capacity = 4;     ///< frames per camera between its source and the fusion core
  int state_capacity = 1024;  ///< propagated states between the fusion core and the publisher
};

/// The Foxglove WebSocket server (foxglove.websocket.v1): Foxglove Studio connects to
/// ws://ADDRESS:PORT and sees posed's topics live.
struct FoxgloveSection {
  bool enabled = false;
  std::string address = "127.0.0.1";  ///< where it listens; loopback unless asked otherwise
  int port = 8765;                    ///< 0: an ephemeral port (logged)
  double max_queued_mb = 8;           ///< per client; beyond this a slow client loses messages
};

/// The mapping stage (core/mapping, docs/mapping.md): keyframes, loop closure, the pose graph and
/// map -> odom. Keyframes are the estimator's (estimator.keyframe_distance_m, _angle_deg).
struct MappingSection {
  bool loop_closure = true;      ///< look for loops and publish map -> odom
  double min_separation_s = 30;  ///< a loop joins keyframes at least this far apart [s]
  double search_radius_m = 8;    ///< candidates by distance within this of the estimate [m]
  double scan_context_max_distance = 0.25;  ///< candidates by descriptor at most this distance
  int attempt_every_keyframes = 2;          ///< loops are looked for at every n-th keyframe [1]
  double keyframe_voxel_m = 0.3;            ///< keyframe clouds kept at this resolution [m]
  double keyframe_max_range_m = 120;        ///< and to this range [m]
  double scan_context_max_range_m = 80;     ///< descriptors reach this far [m]
  double max_rms_m = 0.1;                   ///< a verified loop's point-to-plane RMS at most [m]
  double min_overlap = 0.5;                 ///< and its overlap at least [0..1]
  double min_constraint = 0.02;  ///< and its weakest direction's information share [0..1]
  int queue_capacity = 64;       ///< scans waiting for the mapping thread (live) [1]
  /// odometry edges between keyframes widen by this per metre of degenerate matching [m/m]
  double degenerate_sigma_per_m = 0.5;
  double degenerate_rotation_sigma_per_m = 0.05;  ///< [rad/m]
  double loop_max_correction_sigmas = 8;          ///< [sigma]; 0: no plausibility test
  /// a keyframe this near an older one with a cloud, while loops vouch for the map there, keeps
  /// no cloud of its own: a patrol does not grow the map; 0: every keyframe keeps its cloud [m]
  double mapped_keyframe_distance_m = 1.5;
  // Localisation on a prior map (posed --map DIR).
  double localise_every_m = 2.0;     ///< localised: a registration onto the map this often [m]
  double localise_max_range_m = 60;  ///< localising: scans are cut to this range [m]
  double localise_scan_context_max_distance = 0.4;  ///< localising: descriptor lookups
  double first_fix_min_constraint = 0.05;           ///< localising: a first fix's weakest direction
  double lost_after_m = 25.0;  ///< travel without a verified fix after which it is lost [m]
  /// start from the pose below rather than look the place up by descriptor (as hdl_localization's
  /// specify_init_pose; rt/initialpose does the same at run time)
  bool initial_pose_given = false;
  double initial_x_m = 0;      ///< base_link in the map [m]
  double initial_y_m = 0;      ///< [m]
  double initial_z_m = 0;      ///< [m]
  double initial_yaw_deg = 0;  ///< heading about the map's z [deg]
};

struct WatchdogSection {
  double stage_deadline_s = 1.0;  ///< a stage silent this long stops WATCHDOG=1 [s]
};

struct PosedConfig {
  DdsSection dds;
  PublishSection publish;
  ImuSection imu;
  SyntheticImuSection synthetic_imu;
  LidarSection lidar;
  CameraSection visible_camera;
  CameraSection thermal_camera;
  DepthCameraSection depth_camera;
  RealsenseImuSection realsense_imu;
  SyncSection sync;
  ExtrinsicsSection extrinsics;
  EstimatorSection estimator;
  FrontendSection frontend;
  ThreadsSection threads;
  QueuesSection queues;
  WatchdogSection watchdog;
  FoxgloveSection foxglove;
  MappingSection mapping;
};

}  // namespace posed::config
