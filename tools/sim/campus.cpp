#include "tools/sim/campus.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "tools/sim/path_layout.hpp"

namespace posed::sim {
namespace {

constexpr double kRoadHalfWidth = 3.5;  // two lanes [m]
/// Nothing but the ground and paint this close to the open stretch's centre line [m]: posed's
/// lidar-inertial odometry holds on to whatever the lidar sees out to its 120 m. Measured on seed
/// 31, one pass (tools/eval-sim campus 300 31): with everything but the ground 80 m off (kerbs
/// 30 m) it drifted 0.5 m at worst; 90 m (kerbs 45 m), 7 m (ATE 3.6 m); 100 m (kerbs 60 m), 57 m.
/// On an earlier, smaller layout: 30 m with kerbs and bollards along the stretch, 5 cm (no drift);
/// nothing but the ground within 60 m, the scans flagged degenerate and still 4 cm (the
/// buildings beyond held it).
constexpr double kOpenClear = 90.0;
/// No kerbs this close to the open stretch: kerbs along a bend pin the lidar by themselves [m]
constexpr double kOpenKerbClear = 45.0;
constexpr double kSampleStep = 1.0;  // road samples for the clearance checks [m]

/// A thing standing on the campus, seen from above: a rectangle yawed about z.
struct Footprint {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double hx = 0, hy = 0, yaw = 0;
};

/// Whether two footprints come within `gap_m` of each other (their separating axes; a little
/// conservative at the corners).
bool too_close(const Footprint& a, const Footprint& b, double gap_m) {
  const Eigen::Vector2d axes[4] = {{std::cos(a.yaw), std::sin(a.yaw)},
                                   {-std::sin(a.yaw), std::cos(a.yaw)},
                                   {std::cos(b.yaw), std::sin(b.yaw)},
                                   {-std::sin(b.yaw), std::cos(b.yaw)}};
  const Eigen::Vector2d d = b.c - a.c;
  for (const Eigen::Vector2d& n : axes) {
    const double ra = a.hx * std::abs(n.dot(axes[0])) + a.hy * std::abs(n.dot(axes[1]));
    const double rb = b.hx * std::abs(n.dot(axes[2])) + b.hy * std::abs(n.dot(axes[3]));
    if (std::abs(d.dot(n)) > ra + rb + gap_m) {
      return false;
    }
  }
  return true;
}

/// The ring road through waypoints on a lemniscate of Gerono, x = A(t) sin t,
/// y = B(t) sin t cos t, with A(t) = a_mid + a_diff sin t so that the lobe towards +x is the
/// longer (the open stretch's 90 m of nothing takes most of it), and B(t) = b_mid + b_diff sin t
/// making it wider or narrower than the other. a_mid 155-175 m, a_diff 20-30 m, b_mid 80-100 m,
/// |b_diff| < 10 m: 750-860 m around, the branches crossing at the origin at 50-65°, no bend
/// tighter than ~20 m in radius (a campus road's corner, taken at 3-4 m/s). Smooth: waypoints
/// jittered one by one make bends of a few metres.
std::vector<Eigen::Vector2d> figure_eight(ScenarioRng& rng) {
  const double a_mid = uniform(rng, 155, 175), a_diff = uniform(rng, 20, 30);
  const double b_mid = uniform(rng, 80, 100), b_diff = uniform(rng, -10, 10);
  constexpr int kWaypoints = 36;
  std::vector<Eigen::Vector2d> pts;
  for (int i = 0; i < kWaypoints; ++i) {
    const double t = 2 * std::numbers::pi * i / kWaypoints;
    const double s = std::sin(t);
    pts.emplace_back((a_mid + a_diff * s) * s, (b_mid + b_diff * s) * s * std::cos(t));
  }
  return pts;
}

/// Builds the campus step by step; each step draws from the one stream in its turn.
class CampusBuilder {
 public:
  CampusBuilder(World& w, ScenarioRng& rng) : w_(w), rng_(rng) {
    shape_.road = PeriodicSpline2(figure_eight(rng_));
    shape_.road_half_width_m = kRoadHalfWidth;
    road_samples_ = sample_path(shape_.road, kSampleStep);
    add_materials();
  }

  /// The open stretch, 85-110 m centred on the far end of the larger lobe: the part of the road
  /// farthest from the rest of the campus, so that its 90 m of nothing costs the fewest buildings.
  void open_stretch() {
    std::size_t tip = 0;
    for (std::size_t i = 1; i < road_samples_.size(); ++i) {
      if (road_samples_[i].x() > road_samples_[tip].x()) {
        tip = i;
      }
    }
    const double L = shape_.road.length();
    shape_.open_length_m = uniform(rng_, 85, 110);
    shape_.open_from_u_m =
        std::fmod(static_cast<double>(tip) * kSampleStep - 0.5 * shape_.open_length_m + L, L);
    for (double s = 0; s <= shape_.open_length_m; s += kSampleStep) {
      open_samples_.push_back(path_frame(shape_.road, shape_.open_from_u_m + s).p);
    }
    tip_ = path_frame(shape_.road, static_cast<double>(tip) * kSampleStep);
  }

  /// A football pitch beyond the open stretch: grass a centimetre above the paving (the lidar
  /// cannot tell), white lines for the cameras, and what stands on it far from the road: the
  /// goals, floodlight masts and a clubhouse, each only where it keeps 90 m from the stretch
  /// (the far masts, as a rule: the distant, sparse things).
  void sports_field() {
    const Eigen::Vector2d out = tip_.n.x() > 0 ? tip_.n : Eigen::Vector2d(-tip_.n);
    const double half_len = 52.5, half_wid = 34.0;  // a 105 x 68 m pitch
    const Eigen::Vector2d centre = tip_.p + (kRoadHalfWidth + 10 + half_wid) * out;
    const Eigen::Vector2d along = tip_.t;
    const auto at = [&](double a, double b) -> Eigen::Vector2d {
      return centre + a * along + b * out;
    };
    const auto flat = [&](const Eigen::Vector2d& c, double hx, double hy, double top_m,
                          std::uint32_t material) {
      w_.add_yawed({c.x(), c.y(), top_m - 0.15}, {hx, hy, 0.15}, tip_.yaw, material);
    };
    flat(centre, half_len + 8, half_wid + 6, 0.01, grass_);
    for (const double b : {-half_wid, half_wid}) {
      flat(at(0, b), half_len, 0.06, 0.012, line_);  // touchlines
    }
    for (const double a : {-half_len, 0.0, half_len}) {
      flat(at(a, 0), 0.06, half_wid, 0.012, line_);  // goal lines, halfway line
    }
    for (const double a : {-half_len, half_len}) {
      // Posts 7.32 m apart, a crossbar at 2.44 m.
      const Eigen::Vector2d g = at(a, 0);
      if (!clear_of_path(open_samples_, g, 0.1, 3.8, tip_.yaw, kOpenClear)) {
        continue;
      }
      for (const double b : {-3.66, 3.66}) {
        const Eigen::Vector2d p = at(a, b);
        w_.add_yawed({p.x(), p.y(), 1.22}, {0.06, 0.06, 1.22}, tip_.yaw, white_);
      }
      w_.add_yawed({g.x(), g.y(), 2.4}, {0.06, 3.72, 0.06}, tip_.yaw, white_);
    }
    for (const double a : {-half_len - 6, half_len + 6}) {
      for (const double b : {-half_wid - 4, half_wid + 4}) {
        const Footprint mast{at(a, b), 0.25, 0.25, tip_.yaw};
        if (!free(mast, kRoadHalfWidth + 3, kOpenClear, 1.0)) {
          continue;
        }
        const double h = uniform(rng_, 16, 22);
        add(mast, 0, h, white_);
        w_.add_yawed({mast.c.x(), mast.c.y(), h + 0.8}, {0.4, 1.5, 0.8}, tip_.yaw, white_);
      }
    }
    const Footprint clubhouse{at(uniform(rng_, -30, 30), half_wid + 14), 12, 6, tip_.yaw};
    if (free(clubhouse, kRoadHalfWidth + 5, kOpenClear, 3.0)) {
      add(clubhouse, 0, uniform(rng_, 3.5, 5), brick_);
    }
  }

  /// Buildings of varied size on both sides with gaps between them, set back 4-10 m from the
  /// kerb: lecture halls, labs, the odd tower; windows in rows on the road side.
  void buildings() {
    const double L = shape_.road.length();
    for (const double side : {-1.0, 1.0}) {
      for (double u = uniform(rng_, 0, 15); u < L;) {
        const double hx = uniform(rng_, 5, 18), hy = uniform(rng_, 4, 12);
        const double height = rng_() % 6 == 0 ? uniform(rng_, 22, 40) : uniform(rng_, 4, 18);
        const double lateral = kRoadHalfWidth + uniform(rng_, 4, 10) + hy;
        const std::uint32_t facade = facades_[rng_() % facades_.size()];
        const PathFrame f = path_frame(shape_.road, u + hx);
        const Footprint b{f.p + side * lateral * f.n, hx, hy, f.yaw};
        u += 2 * hx + uniform(rng_, 2, 8);
        if (!free(b, kRoadHalfWidth + 5, kOpenClear, 3.0)) {
          continue;
        }
        add(b, 0, height, facade);
        const Eigen::Vector2d wc = f.p + side * (lateral - hy - 0.02) * f.n;
        for (double z = 1.8; z < height - 1; z += 3.4) {
          if (rng_() % 6 != 0) {
            w_.add_yawed({wc.x(), wc.y(), z}, {hx * 0.85, 0.03, 0.7}, f.yaw, glass_);
          }
        }
      }
    }
  }

  /// Kerbs (12 cm) along both edges of the road, broken where the other branch crosses and
  /// missing along the open stretch, which has painted edge lines instead; a dashed centre line.
  void kerbs_and_markings() {
    const double L = shape_.road.length();
    constexpr double kKerbHalf = 1.5;
    for (const double side : {-1.0, 1.0}) {
      for (double u = 0; u < L; u += 2 * kKerbHalf) {
        const PathFrame f = path_frame(shape_.road, u + kKerbHalf);
        const Eigen::Vector2d c = f.p + side * (kRoadHalfWidth + 0.1) * f.n;
        // Own centre line at 3.5 m less the segment's sagitta on a bend; the crossing branch
        // nearer.
        if (!clear_of_path(road_samples_, c, kKerbHalf, 0.1, f.yaw, kRoadHalfWidth - 0.3)) {
          continue;
        }
        if (clear_of_path(open_samples_, c, kKerbHalf, 0.1, f.yaw, kOpenKerbClear)) {
          w_.add_yawed({c.x(), c.y(), 0.06}, {kKerbHalf, 0.1, 0.06}, f.yaw, kerb_);
        } else {
          const Eigen::Vector2d e = f.p + side * (kRoadHalfWidth - 0.2) * f.n;
          w_.add_yawed({e.x(), e.y(), -0.0225}, {kKerbHalf, 0.06, 0.0275}, f.yaw, line_);
        }
      }
    }
    for (double u = uniform(rng_, 0, 6); u < L; u += 6) {
      const PathFrame f = path_frame(shape_.road, u);
      w_.add_yawed({f.p.x(), f.p.y(), -0.0225}, {1.5, 0.06, 0.0275}, f.yaw, line_);
    }
  }

  /// Rows of cars in parking bays beside the kerb, some bays empty; a few engines still warm.
  void parked_cars() {
    const double L = shape_.road.length();
    for (const double side : {-1.0, 1.0}) {
      for (double u = uniform(rng_, 0, 60); u < L; u += uniform(rng_, 60, 160)) {
        const int bays = 3 + static_cast<int>(rng_() % 8);
        for (int k = 0; k < bays; ++k) {
          const std::uint64_t draw = rng_();
          if (draw % 4 == 0) {
            continue;  // an empty bay
          }
          const PathFrame f = path_frame(shape_.road, u + 5.5 * k);
          const Footprint car{f.p + side * (kRoadHalfWidth + 1.4) * f.n, 2.2, 0.9, f.yaw};
          if (!free(car, kRoadHalfWidth + 0.4, kOpenClear, 0.3)) {
            continue;
          }
          add(car, 0, 1.45, cars_[(draw / 4) % cars_.size()]);
        }
      }
    }
  }

  /// Trees along the pavements with gaps, lamp posts, benches facing the road.
  void street_furniture() {
    const double L = shape_.road.length();
    for (const double side : {-1.0, 1.0}) {
      for (double u = uniform(rng_, 0, 10); u < L; u += uniform(rng_, 7, 16)) {
        const double crown = uniform(rng_, 1.2, 2.2), trunk = uniform(rng_, 2.2, 3.2);
        const double crown_h = uniform(rng_, 2.5, 5.0), turn = uniform(rng_, 0, 1.5);
        if (rng_() % 4 == 0) {
          continue;  // a gap in the row
        }
        const PathFrame f = path_frame(shape_.road, u);
        // Turned, the crown's corner reaches √2 of its half width towards the road.
        const Footprint t{f.p + side * (kRoadHalfWidth + 1.0 + crown * std::numbers::sqrt2) * f.n,
                          crown, crown, f.yaw + turn};
        if (!free(t, kRoadHalfWidth + 0.8, kOpenClear, 0.5)) {
          continue;
        }
        w_.add_yawed({t.c.x(), t.c.y(), trunk / 2}, {0.2, 0.2, trunk / 2}, t.yaw, bark_);
        w_.add_yawed({t.c.x(), t.c.y(), trunk - 0.3 + crown_h / 2}, {crown, crown, crown_h / 2},
                     t.yaw, leaves_);
        placed_.push_back(t);
      }
      for (double u = uniform(rng_, 0, 20); u < L; u += uniform(rng_, 28, 40)) {
        const PathFrame f = path_frame(shape_.road, u);
        const Footprint pole{f.p + side * (kRoadHalfWidth + 0.5) * f.n, 0.07, 0.07, f.yaw};
        if (!free(pole, kRoadHalfWidth + 0.3, kOpenClear, 0.3)) {
          continue;
        }
        add(pole, 0, 6.0, pole_);
        // The lamp head on a short arm over the pavement, not the road.
        const Eigen::Vector2d head = f.p + side * (kRoadHalfWidth + 0.9) * f.n;
        w_.add_yawed({head.x(), head.y(), 6.0}, {0.25, 0.5, 0.08}, f.yaw, pole_);
      }
      for (double u = uniform(rng_, 0, 30); u < L; u += uniform(rng_, 25, 60)) {
        const PathFrame f = path_frame(shape_.road, u);
        const double lateral = kRoadHalfWidth + uniform(rng_, 2.5, 4.0);
        const Footprint bench{f.p + side * lateral * f.n, 0.9, 0.3, f.yaw};
        if (!free(bench, kRoadHalfWidth + 1.0, kOpenClear, 0.3)) {
          continue;
        }
        add(bench, 0, 0.45, wood_);
        const Eigen::Vector2d back = f.p + side * (lateral + 0.26) * f.n;
        w_.add_yawed({back.x(), back.y(), 0.6}, {0.9, 0.04, 0.4}, f.yaw, wood_);
      }
    }
  }

  CampusShape shape() const { return shape_; }

 private:
  void add_materials() {
    // A sunny day: sunlit paving and cars warm, shaded facades near the air (18 °C).
    brick_ = w_.add_material({30, 0.35, kTextureBricks, 0.6, 21, 0, {0.4, 0.5, 0.75}});
    facades_ = {brick_, w_.add_material({40, 0.5, kTextureNoise, 0.3, 20, 0, {0.85, 0.85, 0.85}}),
                w_.add_material({45, 0.55, kTextureChecker, 0.25, 19, 0, {0.8, 0.82, 0.85}})};
    glass_ = w_.add_material({8, 0.15, kTextureChecker, 0.4, 16, 0, {0.6, 0.5, 0.4}});
    grass_ = w_.add_material({45, 0.22, kTextureNoise, 0.35, 20, 0, {0.25, 0.7, 0.35}});
    line_ = w_.add_material({90, 0.8, kTexturePlain, 0, 22, 0, {1, 1, 1}});
    white_ = w_.add_material({60, 0.75, kTexturePlain, 0, 21, 0, {0.95, 0.95, 0.95}});
    kerb_ = w_.add_material({35, 0.55, kTextureNoise, 0.2, 24, 0, {0.85, 0.85, 0.85}});
    bark_ = w_.add_material({20, 0.2, kTextureNoise, 0.4, 18, 0, {0.2, 0.3, 0.4}});
    leaves_ = w_.add_material({40, 0.2, kTextureNoise, 0.6, 17, 0, {0.2, 0.55, 0.25}});
    pole_ = w_.add_material({35, 0.3, kTexturePlain, 0, 22, 0, {0.5, 0.5, 0.5}});
    wood_ = w_.add_material({30, 0.4, kTextureStripes, 0.3, 23, 0, {0.3, 0.45, 0.6}});
    cars_ = {w_.add_material({25, 0.4, kTexturePlain, 0, 28, 0, {0.2, 0.2, 0.7}}),
             w_.add_material({45, 0.7, kTexturePlain, 0, 26, 0, {0.9, 0.9, 0.9}}),
             w_.add_material({20, 0.15, kTexturePlain, 0, 32, 0, {0.2, 0.2, 0.2}}),
             w_.add_material({25, 0.4, kTexturePlain, 0, 45, 0, {0.6, 0.3, 0.2}})};
  }

  /// Whether `f` keeps `road_m` from the road's centre line, `open_m` from the open stretch's
  /// and `gap_m` from everything placed so far.
  bool free(const Footprint& f, double road_m, double open_m, double gap_m) const {
    if (!clear_of_path(road_samples_, f.c, f.hx, f.hy, f.yaw, road_m) ||
        !clear_of_path(open_samples_, f.c, f.hx, f.hy, f.yaw, open_m)) {
      return false;
    }
    return std::none_of(placed_.begin(), placed_.end(),
                        [&](const Footprint& p) { return too_close(p, f, gap_m); });
  }

  /// A box standing on the ground over `f`, from `z0` to `z0 + height` [m].
  void add(const Footprint& f, double z0, double height, std::uint32_t material) {
    w_.add_yawed({f.c.x(), f.c.y(), z0 + height / 2}, {f.hx, f.hy, height / 2}, f.yaw, material);
    placed_.push_back(f);
  }

  World& w_;
  ScenarioRng& rng_;
  CampusShape shape_;
  std::vector<Eigen::Vector2d> road_samples_, open_samples_;
  PathFrame tip_{};
  std::vector<Footprint> placed_;
  std::uint32_t brick_ = 0, glass_ = 0, grass_ = 0, line_ = 0, white_ = 0, kerb_ = 0;
  std::uint32_t bark_ = 0, leaves_ = 0, pole_ = 0, wood_ = 0;
  std::vector<std::uint32_t> facades_, cars_;
};

}  // namespace

CampusShape build_campus(World& world, ScenarioRng& rng) {
  CampusBuilder b(world, rng);
  b.open_stretch();
  b.sports_field();
  b.buildings();
  b.kerbs_and_markings();
  b.parked_cars();
  b.street_furniture();
  return b.shape();
}

}  // namespace posed::sim
