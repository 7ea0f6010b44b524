#pragma once
// The camera side of the fusion core (issue 9): visible and thermal frames paired by stamp
// (StreamPairer), the thermal frame's rotation to its partner's stamp from the gyro, recent
// lidar points in the camera frame for depth (DepthCloud, at the pose the estimator gives for
// the frame's stamp), and the visual-thermal front end (core/vision) run on each visible frame
// event. Pure and deterministic like the rest of the core: it runs on the fusion thread, in the
// order the fusion stage hands measurements over.
//
// Events. The front end runs at the visible camera's rate in every mode, so the three modes see
// the same events and compare (the paper's Table 2): visible mode uses the visible frame,
// thermal mode its thermal partner (registered into the visible frame), fused mode both. A rig
// without a visible camera runs thermal mode on every thermal frame. An event is processed once
// the IMU covers both its stamps (the rotation between them is integrated from the gyro).
//
// Its output, per frame, is the features (id, normalised coordinates, depth) and per-stream
// quality (confidence, covariance scale omega) of seed 002; the figures summarise them.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "core/estimator/fusion_core.hpp"
#include "core/fusion/depth_cloud.hpp"
#include "core/fusion/static_track_filter.hpp"
#include "core/measurements.hpp"
#include "core/sync/imu_buffer.hpp"
#include "core/sync/pose_interpolation.hpp"
#include "core/sync/stream_pairer.hpp"
#include "core/vision/visual_frontend.hpp"

namespace posed::fusion {

/// The D435i's depth node as a source of feature depth where the lidar gives none: the floor a
/// metre or two ahead and the walls beside the robot fall between a VLP-32C's lower rings or
/// below them, while the depth image covers them densely (4 mm at 1 m). Each frame event uses
/// the depth image nearest its stamp, moved to it by the estimator's poses.
struct DepthImageConfig {
  bool enabled = true;  ///< false: depth images are dropped on arrival
  /// the rectified depth image (the left IR imager): pinhole, no distortion [px]
  double fx = 390.43, fy = 390.43, cx = 331.39, cy = 242.19;
  /// the depth frame in the visible camera frame
  Eigen::Isometry3d T_cam_depth = Eigen::Isometry3d::Identity();
  int stride_px = 4;  ///< one point per stride x stride pixels [px]
  /// nearer depths are left out (the robot itself) [m]
  double min_range_m = 0.3;
  /// further depths are left out: the stereo error grows with z^2 (37 mm at 3 m on a D435i,
  /// against a few centimetres for the lidar at any range) [m]
  double max_range_m = 4.0;
  /// a depth image further than this from a frame's stamp is not used for it [ns]
  Duration max_offset = Duration::from_ms(40);
};

struct CameraFrontEndConfig {
  /// the front end whose output goes to the back end; its `mode` is the primary mode
  vision::FrontendConfig frontend;
  /// further front ends run on the same events in these modes, for comparison only
  /// (`posectl inspect frontend`); their figures are in compare_figures()
  std::vector<vision::FrontendMode> compare_modes;
  /// the visible camera in the IMU (base_link) frame
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();
  /// the lidar in the IMU frame (the depth cloud keeps points in front of the camera)
  Eigen::Isometry3d T_imu_lidar = Eigen::Isometry3d::Identity();
  /// which cameras the rig has (a rig without a visible camera runs thermal mode per frame)
  bool has_visible = true;
  bool has_thermal = true;
  /// |thermal - visible| of a pair, and the frames each stream may hold pending
  StreamPairerConfig pairing{.tolerance = Duration::from_ms(20), .pending_capacity = 3};
  /// How far behind the newest IMU sample a frame may still arrive [ns]: 0 when the fusion
  /// stage hands measurements over in stamp order (replays); live, the cameras' latency.
  Duration arrival_lag = Duration::from_ns(0);
  DepthCloudConfig depth;
  DepthImageConfig depth_image;
  /// tracks fixed to the camera are dropped and the others verified (StaticTrackFilter); false:
  /// every track counts as verified
  bool drop_static_tracks = true;
  StaticTrackConfig static_tracks;  ///< focal_px is set from the visible camera
};

/// Sees every frame a front end processed, with the front end (its images), e.g. to annotate.
class FrontendObserver {
 public:
  virtual ~FrontendObserver() = default;
  virtual void on_frame(const vision::FrontendFrame& frame,
                        const vision::VisualFrontend& frontend) = 0;
};

class CameraFrontEnd {
 public:
  explicit CameraFrontEnd(const CameraFrontEndConfig& config);
  ~CameraFrontEnd();
  CameraFrontEnd(const CameraFrontEnd&) = delete;
  CameraFrontEnd& operator=(const CameraFrontEnd&) = delete;

  void add_imu(const ImuSample& sample);
  /// The estimator's states (poses for the depth cloud's camera pose).
  void add_state(const NavState& state);
  /// A scan the estimator matched (its points join the depth cloud).
  void add_scan(const MatchedScan& scan);
  /// A visible or thermal frame, or a depth image (CameraStream::kDepth, PixelFormat::kDepth16).
  void add_image(CameraStream stream, Image image);
  /// Processes every event that can be decided and that the IMU covers.
  void process(const Eigen::Vector3d& gyro_bias_radps);

  void set_observer(FrontendObserver* observer) { observer_ = observer; }
  /// The back end that turns the frames into factors (CameraFactors); called before the observer.
  void set_back_end(FrontendObserver* back_end) { back_end_ = back_end; }
  /// The primary front end's figures.
  const CameraFigures& figures() const { return runs_.front().figures; }
  /// The comparison front ends' figures, in compare_modes order.
  std::vector<CameraFigures> compare_figures() const;
  const StreamPairerCounters& pairing() const { return pairer_.counters(); }

 private:
  struct Event {
    std::optional<Image> visible;
    std::optional<Image> thermal;
    HostTime stamp;   // the tracked image's: the visible frame's, else the thermal frame's
    HostTime latest;  // the later of the two stamps: the IMU must cover it
  };
  struct Run {
    std::unique_ptr<vision::VisualFrontend> frontend;
    vision::FrontendFrame frame;
    CameraFigures figures;
    std::unique_ptr<StaticTrackFilter> static_tracks;
  };
  /// Verifies the run's tracks that move with the world and drops those fixed to the camera
  /// (StaticTrackFilter).
  void drop_static_tracks(Run& run);
  void run_event(Event& event, const Eigen::Vector3d& gyro_bias_radps);
  void account(Run& run, vision::FrontendStatus status);
  /// The points of the depth image nearest `stamp` in the camera frame at `stamp`, into
  /// p_depth_cam_m_ (cleared first); false when there is none close enough or no pose.
  bool depth_image_points(HostTime stamp, const Eigen::Isometry3d& T_map_cam);

  CameraFrontEndConfig config_;
  StreamPairer<Image, Image> pairer_;
  ImuBuffer imu_;
  PoseHistory poses_;
  DepthCloud depth_;
  std::deque<Event> ready_;
  std::vector<Run> runs_;  // the primary first, then compare_modes
  FrontendObserver* observer_ = nullptr;
  FrontendObserver* back_end_ = nullptr;
  std::uint64_t last_scan_index_ = 0;
  std::vector<ImuSample> scratch_;
  std::vector<Eigen::Vector3f> p_cam_m_;
  std::deque<Image> depth_images_;  ///< the newest few, in arrival (stamp) order
  std::vector<Eigen::Vector3f> p_depth_cam_m_;
  /// the same points from the thermal camera's origin (thermal mode's camera, see run_event)
  std::vector<Eigen::Vector3f> p_thermal_origin_m_;
  std::vector<Eigen::Vector3f> p_depth_thermal_origin_m_;
  std::vector<std::uint64_t> fixed_ids_;
  std::optional<std::uint64_t> last_thermal_hash_;  ///< of the last thermal frame processed
};

}  // namespace posed::fusion
