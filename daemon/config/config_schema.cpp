#include "daemon/config/config_schema.hpp"

namespace posed::config {
namespace {

// F(key, member, default, unit, min, max, choices, description)
#define F(key, member, def, unit, lo, hi, choices, desc)                                        \
  Field {                                                                                       \
    key, [](PosedConfig& c) -> FieldRef { return &c.member; }, def, unit, lo, hi, choices, desc \
  }

// P(key, member, description): a file path, resolved against the config file's directory.
#define P(key, member, desc)                                                                    \
  Field {                                                                                       \
    key, [](PosedConfig& c) -> FieldRef { return &c.member; }, "\"\"", "", 0, 0, "", desc, true \
  }

// The defaults are the M2DGR rig (DESIGN.md); config/posed.yaml repeats them with the
// resolution of each catch in M2DGR's calibration files.
const Field kSchema[] = {
    F("dds.domain_id", dds.domain_id, "0", "", 0, 232, "", "DDS domain (ROS_DOMAIN_ID)"),
    F("dds.map_frame", dds.map_frame, "map", "", 0, 0, "", "frame_id of published poses"),
    F("dds.base_frame", dds.base_frame, "base_link", "", 0, 0, "",
      "child_frame_id of published poses (the IMU frame)"),
    F("dds.odom_frame", dds.odom_frame, "odom", "", 0, 0, "",
      "REP-105 odom frame: rt/tf carries map -> odom (identity until a map correction) -> base"),
    F("dds.lidar_frame", dds.lidar_frame, "velodyne", "", 0, 0, "",
      "frame of the lidar in rt/tf_static (extrinsics.T_imu_lidar), as the Velodyne driver names "
      "it"),
    F("dds.camera_frame", dds.camera_frame, "camera_color_optical_frame", "", 0, 0, "",
      "frame of the colour camera in rt/tf_static (extrinsics.T_imu_cam), as realsense-ros names "
      "it"),
    F("dds.thermal_frame", dds.thermal_frame, "thermal_optical_frame", "", 0, 0, "",
      "frame of the thermal camera in rt/tf_static (extrinsics.T_imu_cam * T_cam_thermal)"),
    P("dds.cyclonedds_config", dds.cyclonedds_config,
      "Cyclone DDS XML file; empty uses CYCLONEDDS_URI or Cyclone's default"),
    F("dds.initialpose_topic", dds.initialpose_topic, "rt/initialpose", "", 0, 0, "",
      "DDS topic of the initial pose for localisation on a map (--map), as RViz's 2D Pose "
      "Estimate publishes /initialpose; a ROS 2 topic's DDS name (rt/...); empty: none read"),
    P("dds.security.enclave", dds.security.enclave,
      "DDS Security: SROS2 enclave directory (posectl security init DIR makes DIR/enclaves/posed); "
      "or the six files below; none: plain DDS"),
    P("dds.security.identity_ca", dds.security.identity_ca,
      "DDS Security: CA certificate that signed every participant's identity (PEM)"),
    P("dds.security.certificate", dds.security.certificate,
      "DDS Security: posed's identity certificate (PEM)"),
    P("dds.security.private_key", dds.security.private_key,
      "DDS Security: posed's private key (PEM)"),
    P("dds.security.permissions_ca", dds.security.permissions_ca,
      "DDS Security: CA certificate that signed governance and permissions (PEM)"),
    P("dds.security.governance", dds.security.governance,
      "DDS Security: the domain's governance document, signed (S/MIME .p7s)"),
    P("dds.security.permissions", dds.security.permissions,
      "DDS Security: posed's permissions document, signed (S/MIME .p7s)"),

    F("publish.odom_decimation", publish.odom_decimation, "1", "", 1, 1000, "",
      "publish every Nth propagated state on rt/posed/odom"),
    F("publish.odom_decoupled", publish.odom_decoupled, "true", "", 0, 0, "",
      "with a lidar: rt/posed/odom propagated on the IMU thread from the newest optimised state, "
      "never waiting for scan matching, cameras or the window; false: by the back end"),
    F("publish.odom_blend_s", publish.odom_blend_s, "0.1", "s", 0, 2, "",
      "a correction to rt/posed/odom (a new optimised state) is spread over this long; 0 applies "
      "it at once"),
    F("publish.pose_rate_hz", publish.pose_rate_hz, "10", "Hz", 0.1, 1000, "",
      "rt/posed/pose rate while the estimator is strapdown"),
    F("publish.status_rate_hz", publish.status_rate_hz, "1", "Hz", 0.1, 100, "",
      "rt/posed/status rate"),
    F("publish.tf", publish.tf, "true", "", 0, 0, "",
      "rt/tf (map -> odom -> base_link with each pose, off the odometry's thread) and "
      "rt/tf_static (base_link -> lidar, camera, thermal from the extrinsics)"),
    F("publish.tf_max_rate_hz", publish.tf_max_rate_hz, "0", "Hz", 0, 1000, "",
      "at most this many rt/tf messages per second; 0: one with every rt/posed/pose"),
    F("publish.path", publish.path, "true", "", 0, 0, "", "rt/posed/path (nav_msgs/Path)"),
    F("publish.path_rate_hz", publish.path_rate_hz, "1", "Hz", 0.1, 100, "",
      "rt/posed/path messages per second"),
    F("publish.path_min_step_m", publish.path_min_step_m, "0.1", "m", 0, 100, "",
      "a pose joins the path once the base moved this far from the last one kept"),
    F("publish.path_max_poses", publish.path_max_poses, "10000", "", 10, 1000000, "",
      "past this many poses every other old one is dropped (the whole run stays, coarser)"),
    F("publish.diagnostics", publish.diagnostics, "true", "", 0, 0, "",
      "rt/diagnostics (diagnostic_msgs/DiagnosticArray) with each status: one per stream and "
      "one for the estimator"),
    F("publish.cloud", publish.cloud, "true", "", 0, 0, "",
      "rt/posed/cloud (sensor_msgs/PointCloud2): each matched scan deskewed to its end, in the "
      "lidar frame, fields x y z intensity ring time as the ROS 2 Velodyne driver names them; "
      "built off the fusion thread's path and only while someone reads it"),
    F("publish.cloud_max_rate_hz", publish.cloud_max_rate_hz, "0", "Hz", 0, 100, "",
      "at most this many rt/posed/cloud messages per second; 0: every matched scan"),
    F("publish.map", publish.map, "true", "", 0, 0, "",
      "rt/posed/map (sensor_msgs/PointCloud2, transient-local): the local map scans are "
      "matched against, in the map frame"),
    F("publish.map_rate_hz", publish.map_rate_hz, "0.2", "Hz", 0.01, 10, "",
      "rt/posed/map messages per second"),
    F("publish.image", publish.image, "true", "", 0, 0, "",
      "rt/posed/image/compressed (sensor_msgs/CompressedImage, JPEG): the camera front end's "
      "tracked image with its features, coloured by track length, ringed where lidar gives "
      "depth; drawn and encoded off the fusion thread and only while someone reads it"),
    F("publish.image_rate_hz", publish.image_rate_hz, "5", "Hz", 0.1, 60, "",
      "at most this many rt/posed/image/compressed messages per second"),

    F("imu.source", imu.source, "serial", "", 0, 0, "synthetic|serial|can",
      "where IMU samples come from: the synthetic circle, the A9 over serial, or an IMU on a "
      "SocketCAN interface (imu.can_interface, imu.can_mapping)"),
    F("imu.rate_hz", imu.rate_hz, "150", "Hz", 1, 2000, "", "nominal IMU sample rate"),
    F("imu.serial_device", imu.serial_device, "/dev/posed-imu", "", 0, 0, "",
      "A9 serial port (path or /dev/serial/by-id/...)"),
    F("imu.serial_baud", imu.serial_baud, "921600", "baud", 9600, 4000000, "",
      "A9 serial baud rate"),
    F("imu.can_interface", imu.can_interface, "can0", "", 0, 0, "",
      "SocketCAN interface of a CAN IMU (imu.source can)"),
    // A list, not a scalar: config_loader.cpp parses it and checks it with the decoder's own
    // validate(); config/imu-can-example.yaml documents it.
    F("imu.can_mapping", imu.can_mapping, "{}", "", 0, 0, "",
      "which CAN frames carry which IMU field: {complete_on_id, fields: [{id, extended, field, "
      "byte, type, byte_order, scale, offset}]}; used by imu.source can and to replay recorded "
      "or imported CAN frames ({} = none)"),
    F("imu.R_imu_sensor", imu.R_imu_sensor, "[1, 0, 0, 0, 1, 0, 0, 0, 1]", "", 0, 0, "",
      "mounting rotation from the sensor's axes into the IMU frame (row-major 3x3)"),
    F("imu.gyro_noise_density", imu.gyro_noise_density, "2.3417543020438883e-03", "rad/s/sqrt(Hz)",
      0, 1, "", "gyroscope white noise"),
    F("imu.gyro_random_walk", imu.gyro_random_walk, "1.4428407712885209e-05", "rad/s^2/sqrt(Hz)", 0,
      1, "", "gyroscope bias random walk"),
    F("imu.accel_noise_density", imu.accel_noise_density, "3.7686306102624571e-02",
      "m/s^2/sqrt(Hz)", 0, 10, "", "accelerometer white noise"),
    F("imu.accel_random_walk", imu.accel_random_walk, "1.1416642385952368e-03", "m/s^3/sqrt(Hz)", 0,
      10, "", "accelerometer bias random walk"),
    F("imu.gravity_mps2", imu.gravity_mps2, "9.805", "m/s^2", 9.7, 9.9, "",
      "local gravity magnitude"),
    F("imu.clock_kind", imu.clock_kind, "counter_us_32bit", "", 0, 0,
      "counter_us_32bit|us_past_hour|hardware_ns|none",
      "how the IMU stamps samples (the A9: a 32-bit microsecond counter)"),
    F("imu.clock_latency_s", imu.clock_latency_s, "0", "s", 0, 1, "",
      "minimum transport latency from the device stamp to host arrival (not observable)"),

    F("synthetic_imu.rate_hz", synthetic_imu.rate_hz, "200", "Hz", 1, 2000, "",
      "sample rate of the synthetic IMU"),
    F("synthetic_imu.radius_m", synthetic_imu.radius_m, "5", "m", 0.5, 1000, "",
      "radius of the synthetic circle"),
    F("synthetic_imu.speed_mps", synthetic_imu.speed_mps, "1", "m/s", 0, 30, "",
      "cruise speed along the circle"),
    F("synthetic_imu.static_s", synthetic_imu.static_s, "2", "s", 0, 60, "",
      "standing still before moving (for the gravity alignment)"),
    F("synthetic_imu.ramp_s", synthetic_imu.ramp_s, "3", "s", 0.1, 60, "",
      "time to reach cruise speed"),
    F("synthetic_imu.gyro_noise_density", synthetic_imu.gyro_noise_density, "0", "rad/s/sqrt(Hz)",
      0, 1, "", "white noise added to the synthetic gyroscope"),
    F("synthetic_imu.accel_noise_density", synthetic_imu.accel_noise_density, "0", "m/s^2/sqrt(Hz)",
      0, 10, "", "white noise added to the synthetic accelerometer"),
    F("synthetic_imu.seed", synthetic_imu.seed, "1", "", 0, 2147483647, "",
      "seed of the synthetic noise"),
    F("synthetic_imu.hang_after_s", synthetic_imu.hang_after_s, "0", "s", 0, 1e6, "",
      "fault injection: the fake device hangs in read() after this long (0 = never)"),

    F("lidar.enabled", lidar.enabled, "false", "", 0, 0, "", "read the VLP-32C"),
    F("lidar.source", lidar.source, "udp", "", 0, 0, "udp|pcap",
      "udp: the sensor; pcap: a capture (Wireshark, VeloView) played as if live"),
    P("lidar.pcap_file", lidar.pcap_file, "pcap or pcapng capture for lidar.source pcap"),
    F("lidar.pcap_speed", lidar.pcap_speed, "1", "x", 0.01, 1000, "",
      "playback speed of the capture (1 = original timing)"),
    F("lidar.cut_azimuth_deg", lidar.cut_azimuth_deg, "0", "deg", 0, 359.99, "",
      "azimuth where one scan ends and the next begins"),
    F("lidar.address", lidar.address, "192.168.1.201", "", 0, 0, "",
      "sensor IPv4 address; datagrams from other senders are dropped"),
    F("lidar.data_port", lidar.data_port, "2368", "", 1, 65535, "", "UDP port of data packets"),
    F("lidar.position_port", lidar.position_port, "8308", "", 1, 65535, "",
      "UDP port of position (GPRMC) packets"),
    P("lidar.calibration", lidar.calibration,
      "per-laser calibration (VeloView XML, ros-drivers or velodyne_decoder YAML)"),
    F("lidar.min_range_m", lidar.min_range_m, "0.5", "m", 0, 10, "", "returns closer are dropped"),
    F("lidar.max_range_m", lidar.max_range_m, "120", "m", 1, 300, "",
      "returns farther are dropped"),
    F("lidar.rpm", lidar.rpm, "600", "rpm", 300, 1200, "", "configured rotation speed"),
    F("lidar.clock_kind", lidar.clock_kind, "us_past_hour", "", 0, 0,
      "counter_us_32bit|us_past_hour|hardware_ns|none",
      "how the lidar stamps packets (VLP-32C: microseconds past the hour)"),
    F("lidar.clock_latency_s", lidar.clock_latency_s, "0", "s", 0, 1, "",
      "minimum transport latency from the device stamp to host arrival"),

    F("visible_camera.enabled", visible_camera.enabled, "false", "", 0, 0, "",
      "read the D435i colour stream"),
    F("visible_camera.device", visible_camera.device, "\"\"", "", 0, 0, "",
      "V4L2 node, /dev/v4l/by-id/... or serial number"),
    F("visible_camera.source", visible_camera.source, "v4l2", "", 0, 0, "v4l2|aravis",
      "how the camera is read: V4L2 (UVC) or GenICam through Aravis"),
    F("visible_camera.format", visible_camera.format, "yuyv", "", 0, 0,
      "yuyv|uyvy|rgb8|bgr8|mjpeg|y8|y16", "pixel format negotiated with the camera"),
    F("visible_camera.intrinsics_source", visible_camera.intrinsics_source, "factory", "", 0, 0,
      "factory|config",
      "factory: the D435i's own calibration over USB, the values below when it cannot be read; "
      "config: the values below"),
    F("visible_camera.width", visible_camera.width, "640", "px", 1, 8192, "", "image width"),
    F("visible_camera.height", visible_camera.height, "480", "px", 1, 8192, "", "image height"),
    F("visible_camera.rate_hz", visible_camera.rate_hz, "15", "Hz", 1, 120, "", "frame rate"),
    F("visible_camera.fx", visible_camera.fx, "617.971050917033", "px", 1, 1e5, "", "focal x"),
    F("visible_camera.fy", visible_camera.fy, "616.445131524790", "px", 1, 1e5, "", "focal y"),
    F("visible_camera.cx", visible_camera.cx, "327.710279392468", "px", 0, 1e5, "",
      "principal point x"),
    F("visible_camera.cy", visible_camera.cy, "253.976983707814", "px", 0, 1e5, "",
      "principal point y"),
    F("visible_camera.k1", visible_camera.k1, "0.148000794688248", "", -10, 10, "", "radial k1"),
    F("visible_camera.k2", visible_camera.k2, "-0.217835187249065", "", -10, 10, "", "radial k2"),
    F("visible_camera.p1", visible_camera.p1, "0", "", -1, 1, "", "tangential p1"),
    F("visible_camera.p2", visible_camera.p2, "0", "", -1, 1, "", "tangential p2"),
    F("visible_camera.latency_s", visible_camera.latency_s, "0.041", "s", 0, 1, "",
      "least frame arrival minus exposure midpoint (readout, half a frame at 15 Hz, plus USB); "
      "no clock can observe it, so it is configured"),
    F("visible_camera.clock_kind", visible_camera.clock_kind, "hardware_ns", "", 0, 0,
      "counter_us_32bit|us_past_hour|hardware_ns|none",
      "how the camera stamps frames (D435i: hardware clock in the UVC frame metadata; without "
      "metadata, arrival times regularised to the frame period)"),

    F("thermal_camera.enabled", thermal_camera.enabled, "false", "", 0, 0, "", "read the PLUG 617"),
    F("thermal_camera.device", thermal_camera.device, "\"\"", "", 0, 0, "",
      "V4L2 node, /dev/v4l/by-id/..., or GenICam id"),
    F("thermal_camera.source", thermal_camera.source, "v4l2", "", 0, 0, "v4l2|aravis",
      "how the camera is read: V4L2 (UVC) or GenICam through Aravis (device = camera id)"),
    F("thermal_camera.format", thermal_camera.format, "y8", "", 0, 0, "yuyv|mjpeg|y8|y16",
      "pixel format: 8-bit video after the camera's AGC, or y16 raw counts"),
    F("thermal_camera.width", thermal_camera.width, "640", "px", 1, 8192, "", "image width"),
    F("thermal_camera.height", thermal_camera.height, "512", "px", 1, 8192, "", "image height"),
    F("thermal_camera.rate_hz", thermal_camera.rate_hz, "25", "Hz", 1, 120, "", "frame rate"),
    F("thermal_camera.fx", thermal_camera.fx, "435.836180277211", "px", 1, 1e5, "", "focal x"),
    F("thermal_camera.fy", thermal_camera.fy, "435.909430631362", "px", 1, 1e5, "", "focal y"),
    F("thermal_camera.cx", thermal_camera.cx, "324.452753232850", "px", 0, 1e5, "",
      "principal point x"),
    F("thermal_camera.cy", thermal_camera.cy, "255.554320082190", "px", 0, 1e5, "",
      "principal point y"),
    F("thermal_camera.k1", thermal_camera.k1, "-0.436107594318055", "", -10, 10, "", "radial k1"),
    F("thermal_camera.k2", thermal_camera.k2, "0.166413618922992", "", -10, 10, "", "radial k2"),
    F("thermal_camera.p1", thermal_camera.p1, "0", "", -1, 1, "", "tangential p1"),
    F("thermal_camera.p2", thermal_camera.p2, "0", "", -1, 1, "", "tangential p2"),
    F("thermal_camera.latency_s", thermal_camera.latency_s, "0.03", "s", 0, 1, "",
      "arrival minus exposure midpoint (the PLUG 617 over UVC has no clock)"),
    F("thermal_camera.clock_kind", thermal_camera.clock_kind, "none", "", 0, 0,
      "counter_us_32bit|us_past_hour|hardware_ns|none",
      "how the camera stamps frames (PLUG 617 over UVC: none, host arrival only)"),

    // The D435i's depth node. M2DGR recorded no depth and published no depth calibration, so
    // the defaults are a D435's factory calibration at 640x480 (librealsense's sample recording
    // in shared/realdata/realsense_d435: fx = fy = 390.43, cx 331.39, cy 242.19, baseline
    // 50.17 mm, depth units 1 mm) and Intel's D435 figures for the working range.
    F("realsense_imu.enabled", realsense_imu.enabled, "false", "", 0, 0, "",
      "read the D435i's IMU live (IIO HID accel_3d and gyro_3d): the A9's backup"),
    F("realsense_imu.failover", realsense_imu.failover, "true", "", 0, 0, "",
      "while the A9 is silent, the estimate and rt/posed/odom run on the D435i's IMU (live, or "
      "from a recording that has it); back on the A9 when it returns"),
    F("realsense_imu.failover_after_s", realsense_imu.failover_after_s, "0.05", "s", 0.01, 5, "",
      "A9 silence (in sample time) before the D435i's samples take its place"),
    F("realsense_imu.accel_rate_hz", realsense_imu.accel_rate_hz, "250", "Hz", 50, 1000, "",
      "accel_3d sampling frequency (63 or 250 Hz; 100 or 200 on newer firmware)"),
    F("realsense_imu.gyro_rate_hz", realsense_imu.gyro_rate_hz, "200", "Hz", 50, 1000, "",
      "gyro_3d sampling frequency (200 or 400 Hz)"),
    F("realsense_imu.clock_latency_s", realsense_imu.clock_latency_s, "0", "s", 0, 1, "",
      "minimum transport latency, device stamp to arrival"),
    F("realsense_imu.gyro_noise_density", realsense_imu.gyro_noise_density, "2.44e-3",
      "rad/s/sqrt(Hz)", 0, 1, "",
      "gyroscope white noise the estimator weighs its samples with (the BMI055 datasheet's 10x: "
      "quantisation, lever arm and vibration on top)"),
    F("realsense_imu.gyro_random_walk", realsense_imu.gyro_random_walk, "1.0e-4",
      "rad/s^2/sqrt(Hz)", 0, 1, "", "gyroscope bias random walk"),
    F("realsense_imu.accel_noise_density", realsense_imu.accel_noise_density, "1.47e-2",
      "m/s^2/sqrt(Hz)", 0, 10, "",
      "accelerometer white noise the estimator weighs its samples with (the datasheet's 10x)"),
    F("realsense_imu.accel_random_walk", realsense_imu.accel_random_walk, "5.0e-3",
      "m/s^3/sqrt(Hz)", 0, 10, "", "accelerometer bias random walk"),
    F("realsense_imu.gyro_bias_offset_radps", realsense_imu.gyro_bias_offset_radps, "3.6e-3",
      "rad/s", 0, 1, "",
      "1 sigma per axis of its gyroscope bias less the A9's: how far the estimated bias may step "
      "where one IMU's samples follow the other's"),
    F("realsense_imu.accel_bias_offset_mps2", realsense_imu.accel_bias_offset_mps2, "0.058",
      "m/s^2", 0, 5, "", "the same for the accelerometer bias"),
    F("realsense_imu.sysfs_root", realsense_imu.sysfs_root, "/sys/bus/iio/devices", "", 0, 0, "",
      "where the IIO devices are listed (another tree: a HIL replay's, posectl replay --iio)"),
    F("realsense_imu.dev_dir", realsense_imu.dev_dir, "/dev", "", 0, 0, "",
      "where the IIO character devices (iio:deviceN) are"),
    F("depth_camera.enabled", depth_camera.enabled, "false", "", 0, 0, "",
      "read the D435i depth node live (posectl sim: simulate it); a replay uses a recorded depth "
      "stream whatever this says"),
    F("depth_camera.device", depth_camera.device, "\"\"", "", 0, 0, "",
      "V4L2 node of the depth stream, or /dev/v4l/by-id/..."),
    F("depth_camera.source", depth_camera.source, "v4l2", "", 0, 0, "v4l2",
      "how the depth node is read (V4L2 with its D4xx metadata node)"),
    F("depth_camera.format", depth_camera.format, "z16", "", 0, 0, "z16",
      "pixel format of the depth node"),
    F("depth_camera.latency_s", depth_camera.latency_s, "0.041", "s", 0, 1, "",
      "least frame arrival minus exposure midpoint (the ASIC's matching, half a frame at 15 Hz, "
      "plus USB)"),
    F("depth_camera.clock_kind", depth_camera.clock_kind, "hardware_ns", "", 0, 0,
      "hardware_ns|none",
      "how the depth node stamps frames (the D4xx metadata's hardware clock, the colour node's)"),
    F("depth_camera.width", depth_camera.width, "640", "px", 1, 1280, "",
      "depth image width (the D435i sends 640x480 or 848x480 at 15 Hz)"),
    F("depth_camera.height", depth_camera.height, "480", "px", 1, 800, "", "depth image height"),
    F("depth_camera.rate_hz", depth_camera.rate_hz, "15", "Hz", 1, 90, "", "depth frame rate"),
    F("depth_camera.fx", depth_camera.fx, "390.431457519531", "px", 1, 1e5, "",
      "focal x of the rectified left IR imager"),
    F("depth_camera.fy", depth_camera.fy, "390.431457519531", "px", 1, 1e5, "", "focal y"),
    F("depth_camera.cx", depth_camera.cx, "331.387878417969", "px", 0, 1e5, "",
      "principal point x"),
    F("depth_camera.cy", depth_camera.cy, "242.187347412109", "px", 0, 1e5, "",
      "principal point y"),
    F("depth_camera.baseline_m", depth_camera.baseline_m, "0.0501707", "m", 0.001, 1, "",
      "stereo baseline from the left to the right IR imager"),
    F("depth_camera.depth_unit_m", depth_camera.depth_unit_m, "0.001", "m", 1e-6, 0.01, "",
      "metres per Z16 count (the D435i's default depth units)"),
    F("depth_camera.min_range_m", depth_camera.min_range_m, "0.155", "m", 0.01, 10, "",
      "nearer surfaces find no stereo match and read 0 (MinZ = fx * baseline / 126 px of "
      "disparity search)"),
    F("depth_camera.max_range_m", depth_camera.max_range_m, "10", "m", 0.1, 65, "",
      "farther surfaces read 0 (the D435's ideal range ends near 10 m)"),
    F("depth_camera.feature_depth", depth_camera.feature_depth, "false", "", 0, 0, "",
      "camera features the lidar gives no depth take the depth image's (the floor ahead and the "
      "walls beside the robot, between and below the lidar's rings); off by default: on the "
      "simulated rigs it changed no scenario's error beyond its seed-to-seed spread "
      "(docs/estimator.md) and costs 4 % of a replay's speed"),
    F("depth_camera.feature_stride_px", depth_camera.feature_stride_px, "4", "px", 1, 64, "",
      "one depth point per stride x stride pixels goes to the features' depth search"),
    F("depth_camera.feature_min_range_m", depth_camera.feature_min_range_m, "0.3", "m", 0, 10, "",
      "nearer depths are not used for features (the robot itself)"),
    F("depth_camera.feature_max_range_m", depth_camera.feature_max_range_m, "4", "m", 0.2, 65, "",
      "further depths are not used for features: stereo error grows with z^2 (37 mm at 3 m)"),
    F("depth_camera.feature_max_span_m", depth_camera.feature_max_span_m, "0.3", "m", 0.01, 10, "",
      "a feature whose 3 nearest depth points span more straddles a depth edge: no depth"),
    F("depth_camera.feature_max_offset_s", depth_camera.feature_max_offset_s, "0.04", "s", 0, 1, "",
      "a depth image further from a camera frame's stamp is not used for it"),

    F("sync.pairing_tolerance_s", sync.pairing_tolerance_s, "0.02", "s", 0.0001, 0.5, "",
      "visible and thermal frames further apart than this are not paired"),

    F("extrinsics.T_imu_lidar", extrinsics.T_imu_lidar,
      "[1, 0, 0, 0.27255, 0, 1, 0, -0.00053, 0, 0, 1, 0.17954, 0, 0, 0, 1]", "m", 0, 0, "",
      "lidar pose in the IMU frame (row-major 4x4, translation in metres)"),
    F("extrinsics.T_imu_cam", extrinsics.T_imu_cam,
      "[0, 0, 1, 0.57711, -1, 0, 0, 0.00012, 0, -1, 0, 0.83330, 0, 0, 0, 1]", "m", 0, 0, "",
      "visible camera pose in the IMU frame (camera x right, y down, z forward)"),
    F("extrinsics.T_cam_thermal", extrinsics.T_cam_thermal,
      "[1, 0, 0, -0.17, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]", "m", 0, 0, "",
      "thermal camera pose in the visible camera frame"),
    F("extrinsics.T_cam_depth", extrinsics.T_cam_depth,
      "[1, 0, 0, 0.0143, 0, 1, 0, 0.0006, 0, 0, 1, 0.0006, 0, 0, 0, 1]", "m", 0, 0, "",
      "depth (left IR) imager pose in the visible camera frame: 14.3 mm to the colour camera's "
      "right, as the D435's factory calibration records it"),

    F("extrinsics.T_depth_rsimu", extrinsics.T_depth_rsimu,
      "[1, 0, 0, 0.0055, 0, 1, 0, 0.0051, 0, 0, 1, 0.0117, 0, 0, 0, 1]", "m", 0, 0, "",
      "the D435i's IMU in its depth frame (axes as the decoder turns them: the depth frame's; "
      "offset as rs-enumerate-devices -c reports gyro to depth on a D435i)"),

    F("estimator.init_static_s", estimator.init_static_s, "1", "s", 0.05, 30, "",
      "IMU averaged at start for the gravity alignment"),
    F("estimator.init_max_gyro_radps", estimator.init_max_gyro_radps, "0.05", "rad/s", 0.001, 1, "",
      "largest rate still counted as standing still during alignment"),
    F("estimator.window_size", estimator.window_size, "10", "", 2, 50, "",
      "states in the lidar-inertial fixed-lag window"),
    F("estimator.estimate_gravity_tilt", estimator.estimate_gravity_tilt, "true", "", 0, 0, "",
      "estimate the map frame's tilt (gravity's direction in map) in the window: the map is "
      "levelled only as well as the start-up alignment could, and what it misses otherwise "
      "hides in the accelerometer bias, wrong after every turn"),
    F("estimator.gravity_tilt_prior_deg", estimator.gravity_tilt_prior_deg, "1", "deg", 0.01, 10,
      "", "the tilt's prior at a (re)start, 1 sigma per axis"),
    F("estimator.gravity_tilt_release_heading_deg", estimator.gravity_tilt_release_heading_deg,
      "45", "deg", 0, 720, "",
      "the tilt is held (zero, and in no factor) until the heading has spanned this much at "
      "scans whose position the lidar pins: driving one way, or turning where the lidar is "
      "degenerate, a tilt and an accelerometer bias look the same (0: estimated from the start)"),
    F("estimator.solver_iterations", estimator.solver_iterations, "8", "", 1, 100, "",
      "Levenberg-Marquardt iterations of the window per scan"),
    F("estimator.vehicle_motion", estimator.vehicle_motion, "off", "", 0, 0, "off|always|blind",
      "a wheeled or tracked vehicle: the point vehicle_centre_* of base_link moves along "
      "base_link's x only (no sideways or vertical speed). always: on every state; blind: only "
      "where the lidar is weak, no camera gave the state a motion and the vehicle turns at "
      "vehicle_min_yaw_rate_dps or more, where the sideways speed the lidar pins gives the speed "
      "along a corridor's or a roadway's axis. off for a handheld or legged rig"),
    F("estimator.vehicle_min_yaw_rate_dps", estimator.vehicle_min_yaw_rate_dps, "0", "deg/s", 0,
      1000, "", "with vehicle_motion: blind, only on states turning at least this fast"),
    F("estimator.vehicle_lateral_sigma_mps", estimator.vehicle_lateral_sigma_mps, "0.05", "m/s",
      0.001, 10, "", "sideways speed of the vehicle's no-slip point, 1 sigma (wheel slip)"),
    F("estimator.vehicle_vertical_sigma_mps", estimator.vehicle_vertical_sigma_mps, "0.05", "m/s",
      0.001, 10, "", "its vertical speed, 1 sigma (bumps, a slope's change)"),
    F("estimator.vehicle_centre_x_m", estimator.vehicle_centre_x_m, "0", "m", -10, 10, "",
      "the vehicle's no-slip point in base_link (a differential drive's axle middle): x"),
    F("estimator.vehicle_centre_y_m", estimator.vehicle_centre_y_m, "0", "m", -10, 10, "",
      "and its y"),
    F("estimator.vehicle_centre_z_m", estimator.vehicle_centre_z_m, "0", "m", -10, 10, "",
      "and its z"),
    F("estimator.max_speed_mps", estimator.max_speed_mps, "40", "m/s", 1, 200, "",
      "an estimated speed above this is a divergence (re-initialise)"),
    F("estimator.max_gyro_bias_radps", estimator.max_gyro_bias_radps, "0.3", "rad/s", 0.001, 10, "",
      "an estimated gyro bias above this is a divergence"),
    F("estimator.max_accel_bias_mps2", estimator.max_accel_bias_mps2, "2", "m/s^2", 0.01, 20, "",
      "an estimated accelerometer bias above this is a divergence"),
    F("estimator.max_match_jump_m", estimator.max_match_jump_m, "1", "m", 0.01, 100, "",
      "a scan match further than this from the IMU prediction is refused"),
    F("estimator.max_match_jump_deg", estimator.max_match_jump_deg, "11.5", "deg", 0.1, 180, "",
      "a scan match turned more than this from the IMU prediction is refused"),
    F("estimator.degeneracy_handling", estimator.degeneracy_handling, "true", "", 0, 0, "",
      "keep the IMU prediction along directions the scan does not constrain (false: ablation)"),
    F("estimator.degeneracy_translation_threshold", estimator.degeneracy_translation_threshold,
      "10", "", 0, 10000, "", "fewer point constraints than this along a direction: degenerate"),
    F("estimator.degeneracy_rotation_threshold_m2", estimator.degeneracy_rotation_threshold_m2,
      "20", "m^2", 0, 1e6, "", "rotation constraints (squared lever arms) below this: degenerate"),
    F("estimator.degenerate_information_scale", estimator.degenerate_information_scale, "0.01", "",
      0, 1, "",
      "weight of what a degenerate scan says along its degenerate directions (0: nothing; the "
      "cameras then alone pin them)"),
    F("estimator.plane_voxel_m", estimator.plane_voxel_m, "0.4", "m", 0.05, 5, "",
      "downsampling of planar lidar features"),
    F("estimator.edge_voxel_m", estimator.edge_voxel_m, "0.2", "m", 0.05, 5, "",
      "downsampling of edge lidar features"),
    F("estimator.map_radius_m", estimator.map_radius_m, "120", "m", 10, 2000, "",
      "the local map keeps what is within this distance of the robot"),
    F("estimator.map_confirm_s", estimator.map_confirm_s, "0", "s", 0, 60, "",
      "a local-map voxel is matched against only once scans have hit it over this long, so the "
      "trail a moving person or vehicle leaves is not taken for the world (0: at once)"),
    F("estimator.keyframe_distance_m", estimator.keyframe_distance_m, "1", "m", 0.01, 100, "",
      "a scan this far from the last keyframe is a keyframe (exported map poses)"),
    F("estimator.keyframe_angle_deg", estimator.keyframe_angle_deg, "11.5", "deg", 0.1, 180, "",
      "or turned this much"),
    F("estimator.camera_coupling", estimator.camera_coupling, "loose", "", 0, 0,
      "loose|landmarks|loose+landmarks|off",
      "cameras in the estimate: each stream's frame-to-frame motion (lidar depth for scale) as a "
      "between factor per state (seed 002); landmarks, each feature with lidar depth a point fixed "
      "where it was first seen and a reprojection factor per later state that sees it (LVI-SAM's "
      "VIS); or off (the front end only reports)"),
    F("estimator.camera_pixel_sigma_px", estimator.camera_pixel_sigma_px, "1", "px", 0.05, 20, "",
      "feature noise of a frame-to-frame motion: its covariance at omega = 1 (Sigma_base)"),
    F("estimator.camera_quality_weighting", estimator.camera_quality_weighting, "true", "", 0, 0,
      "", "scale each stream's covariance by omega from its image quality (seed 002)"),
    F("estimator.camera_residual_scaling", estimator.camera_residual_scaling, "true", "", 0, 0, "",
      "with two camera streams, also scale each one's covariance by how far its factors sit from "
      "the solution compared with the other's (a variance component estimate): image quality "
      "cannot see a stream whose features are sharp but not where it thinks"),
    F("estimator.camera_thermal_gate_strict", estimator.camera_thermal_gate_strict, "true", "", 0,
      0, "",
      "a thermal or fused frame pair whose features mostly miss where the IMU puts them gives "
      "no motion (the visible stream then trusts the majority): a thermal camera's fixed pattern "
      "on uniform walls holds still while the robot moves"),
    F("estimator.camera_thermal_standby", estimator.camera_thermal_standby, "false", "", 0, 0, "",
      "with frontend.mode visible+thermal, the thermal stream's factors enter the estimate only "
      "while the visible stream's gate is closed (smoke, darkness); its front end runs throughout"),
    F("estimator.camera_min_confidence", estimator.camera_min_confidence, "0.05", "", 0, 1, "",
      "a stream whose image confidence stays below this (3 frames) leaves the estimate"),
    F("estimator.camera_rejoin_confidence", estimator.camera_rejoin_confidence, "0.08", "", 0, 1,
      "", "and returns once it is at or above this for 5 frames"),
    F("estimator.camera_min_gradient", estimator.camera_min_gradient, "0.02", "", 0, 1, "",
      "so does a stream whose gradient metric g (seed 002) stays below this: smoke, darkness, a "
      "covered lens take the edges first"),
    F("estimator.camera_rejoin_gradient", estimator.camera_rejoin_gradient, "0.04", "", 0, 1, "",
      "and it returns once g is at or above this (and the confidence above its threshold)"),
    F("estimator.camera_floor_translation_m", estimator.camera_floor_translation_m, "0.002", "m", 0,
      1, "", "1-sigma added to each camera factor's translation (features are not independent)"),
    F("estimator.camera_strong_lidar_floor_translation_m",
      estimator.camera_strong_lidar_floor_translation_m, "0.002", "m", 0, 1, "",
      "the same where the lidar is strong and settled (see camera_strong_lidar_after_s): 0.03 "
      "keeps a 2-minute open site within about 1 mm of the lidar alone, where 0.002 leaves it up "
      "to 8 mm worse, but cost 10-minute campus drives up to 3 m (docs/estimator.md)"),
    F("estimator.camera_strong_lidar_after_s", estimator.camera_strong_lidar_after_s, "5", "s", 0,
      3600, "",
      "the strong-lidar floor applies only once every scan for this long pinned every direction "
      "(none degenerate or rejected, no restart): until then the cameras help the window find "
      "the speed and biases (0: at once, which cost a 30 s tunnel four times its error)"),
    F("estimator.camera_floor_rotation_deg", estimator.camera_floor_rotation_deg, "0.06", "deg", 0,
      10, "", "1-sigma added to each camera factor's rotation"),
    F("estimator.camera_keyframe_states", estimator.camera_keyframe_states, "5", "", 1, 49, "",
      "a camera motion starts from a keyframe state and ends at each new state, for this many "
      "states (at most window_size - 1); 1: from the previous state only"),
    F("estimator.camera_landmark_gate_px", estimator.camera_landmark_gate_px, "20", "px", 0.5, 1000,
      "",
      "with camera_coupling: landmarks, an observation further than this from where the window "
      "projects its landmark is not added"),
    F("estimator.camera_landmark_outlier_sigma", estimator.camera_landmark_outlier_sigma, "15", "",
      0.5, 1000, "",
      "and a landmark whose newest observation the solve leaves further off than this many pixel "
      "sigmas takes no more"),
    F("estimator.camera_landmark_huber_sigma", estimator.camera_landmark_huber_sigma, "3", "", 0.1,
      1000, "", "Huber threshold of the landmark factors, in pixel sigmas"),
    F("estimator.camera_guess_gate_px", estimator.camera_guess_gate_px, "3", "px", 0, 1000, "",
      "a tracked feature further than this from where the window's predicted motion puts it is "
      "left out of its frame pair's motion (unless that leaves fewer than half); 0: no gate"),
    F("estimator.camera_weak_lidar_guess_gate_px", estimator.camera_weak_lidar_guess_gate_px, "6",
      "px", 0, 1000, "",
      "the same gate within camera_lidar_suspect_window_s of a degenerate scan, where the "
      "predicted speed along the lidar's blind direction can be a quarter off"),
    F("estimator.camera_still_flow_sigma", estimator.camera_still_flow_sigma, "2", "", 0, 100, "",
      "a feature nearer to where it was than to where the predicted motion moves it, by more than "
      "this many pixel sigmas, is left out (a corner of the lamp's shading or lens dirt); 0: off"),
    F("estimator.camera_aperture_max_ratio", estimator.camera_aperture_max_ratio, "0", "", 0, 1000,
      "",
      "a tracked feature weighs in its frame pair's motion by its image patch's structure: along "
      "a direction the patch fixes poorly (a straight edge, where KLT slides) its sigma grows up "
      "to this many times the pixel sigma; 0 or 1: every feature as a corner"),
    F("estimator.camera_degeneracy_translation_threshold",
      estimator.camera_degeneracy_translation_threshold, "10", "", 0, 10000, "",
      "while a camera stream is in the estimate, a scan is degenerate along translations it pins "
      "with fewer point constraints than this (as degeneracy_translation_threshold otherwise)"),
    F("estimator.camera_degenerate_information_scale",
      estimator.camera_degenerate_information_scale, "0", "", 0, 1, "",
      "and what such a scan says along its degenerate directions is weighed by this (0: the "
      "cameras "
      "and the IMU alone; degenerate_information_scale otherwise)"),
    F("estimator.camera_lidar_trusted_constraints", estimator.camera_lidar_trusted_constraints,
      "200", "", 0, 1e6, "",
      "a scan's translation pinned by fewer point constraints than this is checked against the "
      "cameras' motion for the same interval"),
    F("estimator.camera_lidar_consistency_sigma", estimator.camera_lidar_consistency_sigma, "3", "",
      0.5, 100, "",
      "where the scan and the cameras disagree by more than this, the scan says nothing along "
      "that direction (an aliased match, e.g. a roadway's uniform pipes)"),
    F("estimator.camera_lidar_suspect_window_s", estimator.camera_lidar_suspect_window_s, "5", "s",
      0, 3600, "",
      "the scan is checked against the cameras only this long after a scan with a degenerate "
      "direction: where the lidar has not shown it is lost (an open street) its weak directions "
      "are right"),
    F("estimator.camera_blind_weak_lidar_ratio", estimator.camera_blind_weak_lidar_ratio, "0.5", "",
      0, 1, "",
      "where the scan would be checked but the cameras give no motion (gated out by smoke or "
      "darkness, or every frame pair failed), a translation it pins with less than this share of "
      "its best-pinned translation's information says nothing and the IMU carries it (0: off): "
      "in a roadway the scans hold the axis still"),
    F("estimator.pose_selection", estimator.pose_selection, "true", "", 0, 0, "",
      "seed 001's adaptive pose selection: each state starts from the lidar, camera or fused "
      "odometry by the dynamic-threshold rule (false: the IMU prediction)"),

    // The visual-thermal front end (core/vision, docs/frontend.md); runs with a camera enabled.
    F("frontend.mode", frontend.mode, "visible", "", 0, 0,
      "off|visible|thermal|fused|visible+thermal",
      "which image features are tracked on: visible, thermal, their DWT fusion (seed 000), or "
      "visible and thermal as two streams, each weighed by its own image quality (seed 002)"),
    F("frontend.enhance_visible", frontend.enhance_visible, "true", "", 0, 0, "",
      "adaptive gamma and CLAHE on the visible image's V channel (seed 001)"),
    F("frontend.gamma_target_mean", frontend.gamma_target_mean, "0.5", "", 0.05, 0.95, "",
      "mean brightness the adaptive gamma aims for [0..1]"),
    F("frontend.clahe_clip_limit", frontend.clahe_clip_limit, "2", "", 0.5, 40, "",
      "CLAHE histogram clip, in multiples of the uniform bin"),
    F("frontend.thermal_registration", frontend.thermal_registration, "infinity", "", 0, 0,
      "infinity|plane|fov_crop|lidar_depth",
      "thermal onto the visible pixel grid: homography at infinity, a plane at "
      "thermal_plane_depth_m, seed 000's centred FOV crop, or per pixel at the lidar's depth "
      "(a coarse grid; infinity where it has no points)"),
    F("frontend.thermal_plane_depth_m", frontend.thermal_plane_depth_m, "10", "m", 0.5, 1000, "",
      "depth of the registration plane for thermal_registration: plane"),
    F("frontend.thermal_depth_grid_cols", frontend.thermal_depth_grid_cols, "40", "", 1, 640, "",
      "thermal_registration: lidar_depth: cells of the depth grid across the image"),
    F("frontend.thermal_depth_grid_rows", frontend.thermal_depth_grid_rows, "30", "", 1, 480, "",
      "thermal_registration: lidar_depth: cells of the depth grid down the image"),
    F("frontend.rotation_compensation", frontend.rotation_compensation, "true", "", 0, 0, "",
      "warp the thermal frame by the gyro's rotation between its stamp and its visible partner's"),
    F("frontend.thermal_nuc", frontend.thermal_nuc, "false", "", 0, 0, "",
      "scene-based non-uniformity correction: learn the thermal camera's fixed pattern from its "
      "moving video and subtract it, so its corners are the scene's and not the sensor's"),
    F("frontend.thermal_nuc_frames", frontend.thermal_nuc_frames, "100", "frames", 1, 10000, "",
      "moving frames each pixel's learnt offset averages over (the pattern grows between the "
      "camera's flat-field corrections, which start the learning afresh)"),
    F("frontend.own_thread", frontend.own_thread, "true", "", 0, 0, "",
      "run the camera front end on a thread of its own (posed-camera), beside the lidar front "
      "end, joined at each window step, when the cameras are in the estimate; false: on the "
      "fusion thread. The estimate is the same either way"),
    F("frontend.wavelet", frontend.wavelet, "haar", "", 0, 0, "haar|legall53|cdf97",
      "wavelet of the 2-level DWT fusion"),
    F("frontend.fusion_noise_weighted", frontend.fusion_noise_weighted, "true", "", 0, 0, "",
      "detail coefficients chosen by significance over each stream's noise (false: the larger "
      "magnitude, seed 000's eq. 8 as published)"),
    F("frontend.fusion_denoise", frontend.fusion_denoise, "true", "", 0, 0, "",
      "smooth each stream noisier than fusion_denoise_target_sigma (its estimated noise) by a "
      "Gaussian before the fusion"),
    F("frontend.fusion_denoise_target_sigma", frontend.fusion_denoise_target_sigma, "2", "grey",
      0.1, 50, "", "noise level the pre-smoothing aims for"),
    F("frontend.max_features", frontend.max_features, "300", "", 20, 2000, "",
      "point features kept per frame (seed 001: 200-400)"),
    F("frontend.min_feature_distance_px", frontend.min_feature_distance_px, "20", "px", 2, 200, "",
      "least distance between features"),
    F("frontend.ransac_threshold_px", frontend.ransac_threshold_px, "4", "px", 0.1, 10, "",
      "distance to the epipolar line beyond which a track is an outlier (the back end checks "
      "the survivors against the IMU's motion; a tight threshold on a forward-moving camera "
      "drops half of the good tracks)"),
    F("frontend.ransac_max_iterations", frontend.ransac_max_iterations, "200", "", 1, 100000, "",
      "RANSAC draws at most per frame pair: the 99 % confidence for 58 % inliers (OpenCV's "
      "1000: 48 %); where fewer tracks agree (smoke, darkness) its draws cost milliseconds a "
      "frame and the motion is gated out anyway (docs/realtime.md, stop 51)"),
    F("frontend.forward_backward_px", frontend.forward_backward_px, "0.5", "px", 0.05, 10, "",
      "a track is kept when KLT, run back from the new frame, lands within this of where it "
      "started (docs/estimator.md: 1 px tracked 65 % of the simulated corridor's features per "
      "frame instead of 54 %, with better frame-pair motions, but did not make every run better)"),
    F("frontend.klt_window_px", frontend.klt_window_px, "15", "px", 5, 61, "",
      "side of the KLT window (VINS-Mono 21, OpenVINS 15): larger follows faster flow and blurs "
      "depth edges, and costs the square"),
    F("frontend.klt_pyramid_levels", frontend.klt_pyramid_levels, "3", "", 0, 6, "",
      "KLT pyramid levels above the image: each doubles the flow it can follow"),
    F("frontend.lines", frontend.lines, "false", "", 0, 0, "",
      "also track LSD line features (seed 001); several ms per frame"),
    F("frontend.depth_window_s", frontend.depth_window_s, "1", "s", 0, 10, "",
      "lidar scans stacked for feature depth (seed 000)"),
    F("frontend.depth_points_per_scan", frontend.depth_points_per_scan, "20000", "", 1000, 200000,
      "", "points kept of each stacked scan (in front of the camera, evenly thinned)"),
    F("frontend.depth_max_span_m", frontend.depth_max_span_m, "2", "m", 0.1, 20, "",
      "a feature's 3 lidar neighbours spanning more than this give no depth (seed 000)"),
    F("frontend.corner_noise_factor", frontend.corner_noise_factor, "4", "", 0, 1000, "",
      "a new corner's Shi-Tomasi score must exceed this multiple of the image's median score, the "
      "noise floor of an untextured image: corners of noise over static shading or a thermal "
      "camera's fixed pattern never move and would pass for a camera standing still (0: off)"),
    F("frontend.quality_lambda_n", frontend.quality_lambda_n, "0.1", "1/grey", 0.001, 100, "",
      "seed 002's lambda_n: omega = lambda_n (sigma_n + lambda_g (1 - g)), the scale of a "
      "stream's covariance weight"),
    F("frontend.quality_lambda_g", frontend.quality_lambda_g, "10", "grey", 0, 1000, "",
      "seed 002's lambda_g: how much the gradient metric g weighs against the noise sigma_n"),

    // SCHED_FIFO priorities: the maximum (50) must not exceed LimitRTPRIO in posed.service.
    F("threads.imu_source.priority", threads.imu_source.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the IMU source thread (0 = normal scheduling)"),
    F("threads.imu_source.cpu", threads.imu_source.cpu, "-1", "", -1, 1023, "",
      "CPU the IMU source thread is pinned to (-1 = any)"),
    F("threads.lidar_source.priority", threads.lidar_source.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the lidar source thread (0 = normal scheduling)"),
    F("threads.lidar_source.cpu", threads.lidar_source.cpu, "-1", "", -1, 1023, "",
      "CPU the lidar source thread is pinned to (-1 = any)"),
    F("threads.fusion.priority", threads.fusion.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the fusion thread (0 = normal scheduling)"),
    F("threads.fusion.cpu", threads.fusion.cpu, "-1", "", -1, 1023, "",
      "CPU the fusion thread is pinned to (-1 = any)"),
    F("threads.camera_source.priority", threads.camera_source.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the camera source threads (0 = normal scheduling)"),
    F("threads.camera_source.cpu", threads.camera_source.cpu, "-1", "", -1, 1023, "",
      "CPU the camera source threads are pinned to (-1 = any)"),
    F("threads.camera_frontend.priority", threads.camera_frontend.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the camera front end's thread, posed-camera (frontend.own_thread; "
      "0 = normal scheduling)"),
    F("threads.camera_frontend.cpu", threads.camera_frontend.cpu, "-1", "", -1, 1023, "",
      "CPU the camera front end's thread is pinned to (-1 = any); it works beside the fusion "
      "thread, so not the fusion thread's CPU"),
    F("threads.lidar_helpers", threads.lidar_helpers, "1", "threads", 0, 16, "",
      "helper threads for the scan match's correspondence search and the feature extraction, "
      "beside the fusion thread "
      "(posed-lidar-hN; 0 = the fusion thread alone); the poses are the same either way"),
    F("threads.lidar_helper.priority", threads.lidar_helper.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the scan match's helper threads (0 = normal scheduling)"),
    F("threads.lidar_helper.cpu", threads.lidar_helper.cpu, "-1", "", -1, 1023, "",
      "CPU the scan match's helper threads are pinned to (-1 = any); they work while the fusion "
      "thread does, so not the fusion thread's CPU"),
    F("threads.publisher.priority", threads.publisher.priority, "0", "", 0, 50, "",
      "SCHED_FIFO priority of the DDS publisher thread (0 = normal scheduling)"),
    F("threads.publisher.cpu", threads.publisher.cpu, "-1", "", -1, 1023, "",
      "CPU the DDS publisher thread is pinned to (-1 = any)"),

    F("queues.imu_capacity", queues.imu_capacity, "1024", "samples", 8, 1048576, "",
      "each IMU's queue (the A9's, the D435i's) to the fusion core (drop-oldest; a --max-speed "
      "replay, merged in stamp order, uses at most 128 so its streams read the file side by side)"),
    F("queues.scan_capacity", queues.scan_capacity, "4", "scans", 2, 64, "",
      "lidar scans between the lidar source and the fusion core (drop-oldest when live)"),
    F("queues.image_capacity", queues.image_capacity, "4", "frames", 2, 64, "",
      "frames per camera between its source and the fusion core (drop-oldest when live)"),
    F("queues.state_capacity", queues.state_capacity, "1024", "states", 8, 1048576, "",
      "state queue between the fusion core and the publisher (drop-oldest)"),

    F("watchdog.stage_deadline_s", watchdog.stage_deadline_s, "1", "s", 0.01, 60, "",
      "a stage silent this long stops the systemd watchdog"),

    F("foxglove.enabled", foxglove.enabled, "false", "", 0, 0, "",
      "serve posed's topics to Foxglove Studio over the Foxglove WebSocket protocol "
      "(foxglove.websocket.v1, ros2msg schemas, CDR)"),
    F("foxglove.address", foxglove.address, "127.0.0.1", "", 0, 0, "",
      "address the Foxglove server listens on: loopback by default; 0.0.0.0 or a robot's "
      "address to be reached from a laptop (the unit's IPAddressAllow applies)"),
    F("foxglove.port", foxglove.port, "8765", "", 0, 65535, "",
      "TCP port of the Foxglove server (Foxglove Studio's default 8765; 0: any free port, logged)"),
    F("foxglove.max_queued_mb", foxglove.max_queued_mb, "8", "MB", 0.1, 1024, "",
      "messages queued per client before a slow client loses some (it alone)"),

    F("mapping.loop_closure", mapping.loop_closure, "true", "", 0, 0, "",
      "keep keyframes, close loops (Scan Context + GICP verification) in a pose graph on a "
      "thread of its own, and publish the correction as map -> odom (rt/posed/pose in map)"),
    F("mapping.min_separation_s", mapping.min_separation_s, "30", "s", 1, 3600, "",
      "a loop joins keyframes at least this far apart in time"),
    F("mapping.search_radius_m", mapping.search_radius_m, "8", "m", 0, 100, "",
      "loop candidates by distance: an old keyframe this near the current estimate"),
    F("mapping.scan_context_max_distance", mapping.scan_context_max_distance, "0.25", "", 0, 1, "",
      "loop candidates by descriptor (drift beyond the search radius): Scan Context "
      "distance at most this; such a loop must be confirmed by the next attempt"),
    F("mapping.attempt_every_keyframes", mapping.attempt_every_keyframes, "2", "keyframes", 1, 1000,
      "", "look for a loop at every n-th keyframe (registration is the expensive part)"),
    F("mapping.keyframe_voxel_m", mapping.keyframe_voxel_m, "0.3", "m", 0.05, 5, "",
      "keyframe clouds are kept thinned to one point per voxel of this size"),
    F("mapping.keyframe_max_range_m", mapping.keyframe_max_range_m, "120", "m", 5, 130, "",
      "keyframe clouds keep the points this near the sensor (a map keeps it; localising cuts "
      "scans the same): far structure pins a registration where nothing stands near"),
    F("mapping.scan_context_max_range_m", mapping.scan_context_max_range_m, "80", "m", 5, 130, "",
      "Scan Context descriptors cover this range (in 20 rings; a map keeps it)"),
    F("mapping.max_rms_m", mapping.max_rms_m, "0.1", "m", 0.01, 2, "",
      "a loop's registration must fit to this RMS point-to-plane distance"),
    F("mapping.min_overlap", mapping.min_overlap, "0.5", "", 0, 1, "",
      "and overlap this much (share of the query's points near the candidate's)"),
    F("mapping.min_constraint", mapping.min_constraint, "0.02", "", 0, 1, "",
      "and pin every direction of translation at least this much (share of the point-to-plane "
      "information in its weakest direction): a plain corridor cannot close a loop along itself"),
    F("mapping.queue_capacity", mapping.queue_capacity, "64", "scans", 4, 4096, "",
      "scans waiting for the mapping thread; live, a keyframe that finds it full is left out "
      "(counted; the graph bridges it by odometry), a replay waits"),
    F("mapping.degenerate_sigma_per_m", mapping.degenerate_sigma_per_m, "0.5", "m/m", 0, 10, "",
      "an odometry edge of the pose graph is this much less certain per metre the estimator "
      "matched degenerately (an open stretch), so loops correct the drift there"),
    F("mapping.degenerate_rotation_sigma_per_m", mapping.degenerate_rotation_sigma_per_m, "0.05",
      "rad/m", 0, 10, "", "and its rotation this much less certain per such metre"),
    F("mapping.loop_max_correction_sigmas", mapping.loop_max_correction_sigmas, "8", "sigma", 0,
      1e6, "",
      "a verified loop is refused as implausible when its correction is further than this from "
      "where the graph puts the keyframe, in sigmas of the odometry edges between the two "
      "keyframes: a place that looks like another fits as well but asks for a drift the odometry "
      "cannot have; 0: no such test"),
    F("mapping.mapped_keyframe_distance_m", mapping.mapped_keyframe_distance_m, "1.5", "m", 0, 100,
      "",
      "a keyframe this near an older keyframe that keeps its cloud, while a loop closed in the "
      "last 30 keyframes vouches for the map there, keeps only its pose and descriptor: driving "
      "a mapped place again does not grow the map; 0: every keyframe keeps its cloud"),
    F("mapping.localise_every_m", mapping.localise_every_m, "2", "m", 0.1, 100, "",
      "localising on a prior map (posed --map): once localised, register the scan onto the map "
      "after moving this far"),
    F("mapping.localise_max_range_m", mapping.localise_max_range_m, "60", "m", 5, 130, "",
      "localising: a scan's points this near the sensor are registered onto the map (at most "
      "the map's own keyframe range)"),
    F("mapping.localise_scan_context_max_distance", mapping.localise_scan_context_max_distance,
      "0.4", "", 0, 1, "",
      "localising: a descriptor lookup registers onto map keyframes whose Scan Context is at "
      "most this far from the scan's"),
    F("mapping.first_fix_min_constraint", mapping.first_fix_min_constraint, "0.05", "", 0, 1, "",
      "localising: a fix while aligning or lost must pin every direction at least this much "
      "(as mapping.min_constraint; a first fix has no earlier one to agree with)"),
    F("mapping.lost_after_m", mapping.lost_after_m, "25", "m", 1, 10000, "",
      "localising: travel without a verified registration after which the state is lost and the "
      "place is looked up again"),
    F("mapping.initial_pose_given", mapping.initial_pose_given, "false", "", 0, 0, "",
      "localising: start from mapping.initial_* instead of looking the place up by descriptor "
      "(rt/initialpose does the same at run time)"),
    F("mapping.initial_x_m", mapping.initial_x_m, "0", "m", -1e6, 1e6, "",
      "localising: base_link's x in the map at start (with initial_pose_given)"),
    F("mapping.initial_y_m", mapping.initial_y_m, "0", "m", -1e6, 1e6, "", "and its y"),
    F("mapping.initial_z_m", mapping.initial_z_m, "0", "m", -1e6, 1e6, "", "and its z"),
    F("mapping.initial_yaw_deg", mapping.initial_yaw_deg, "0", "deg", -360, 360, "",
      "and its heading about the map's z"),
};

#undef F
#undef P

}  // namespace

std::span<const Field> schema() { return kSchema; }

const Field* find_field(std::string_view key) {
  for (const auto& f : kSchema) {
    if (f.key == key) return &f;
  }
  return nullptr;
}

}  // namespace posed::config
