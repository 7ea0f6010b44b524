#pragma once
// The simulated world: a flat list of boxes (ground slab, walls, poles, buildings, vehicles, rock
// blocks) with materials, plus point lights. Everything the sensors see is a box face, which
// keeps ray casting (lidar), face lookup (cameras) and temperature (thermal) one code path.
//
// Frame `map`: x east, y north, z up; ground at z = 0.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "tools/sim/smoke.hpp"

namespace posed::sim {

/// What a surface looks like to each sensor.
struct Material {
  /// lidar reflectivity as the VLP-32C reports it: 0..100 diffuse, 101..255 retro-reflective [-]
  double reflectivity = 40.0;
  /// diffuse albedo for the visible camera [0..1]
  double albedo = 0.5;
  /// procedural texture (TextureId) painted on the faces
  std::uint8_t texture = 0;
  /// texture contrast: 0 = flat colour, 1 = full-range pattern [0..1]
  double texture_contrast = 0.3;
  /// surface temperature [°C]
  double temperature_c = 15.0;
  /// light the surface emits itself (lamp heads, lit windows) [relative radiance, 1 = white]
  double emission = 0.0;
  /// colour tint (B, G, R) multiplying the albedo [0..1]
  Eigen::Vector3d tint_bgr{1.0, 1.0, 1.0};
};

/// Procedural textures, evaluated in face coordinates [m].
enum TextureId : std::uint8_t {
  kTexturePlain = 0,    ///< no pattern
  kTextureNoise = 1,    ///< blotchy value noise (asphalt, rock, concrete)
  kTextureBricks = 2,   ///< bricks 0.25 x 0.065 m with mortar
  kTextureStripes = 3,  ///< stripes every 1 m (lane markings, corridor panels)
  kTextureChecker = 4,  ///< 0.2 m checkerboard (posters, calibration-like targets)
};

/// An oriented box: `R_map_box` turns box axes into map axes; half extents along box axes.
struct Box {
  /// centre [m]
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
  /// half sizes along the box's own x, y, z [m]
  Eigen::Vector3d half_extent_m = Eigen::Vector3d::Constant(0.5);
  /// orientation: box axes -> map axes
  Eigen::Matrix3d R_map_box = Eigen::Matrix3d::Identity();
  /// index into World::materials
  std::uint32_t material = 0;
};

/// An omnidirectional light with inverse-square falloff (street lights, mine lamps).
struct PointLight {
  /// position [m]
  Eigen::Vector3d p_map_m = Eigen::Vector3d::Zero();
  /// irradiance at 1 m on a surface facing it [relative, 1 = full daylight-ish exposure]
  double intensity = 1.0;
};

struct World {
  std::vector<Box> boxes;
  std::vector<Material> materials;
  std::vector<PointLight> lights;
  /// uniform light from everywhere (daylight, room lighting) [relative, same unit as lights]
  double ambient = 0.05;
  /// apparent sky temperature for the thermal camera (clear night sky is far below air) [°C]
  double sky_temperature_c = -20.0;
  /// sky brightness for the visible camera [0..1]
  double sky_radiance = 0.0;
  /// a lamp carried on the vehicle next to the cameras (mine, corridor) [relative at 1 m]
  double headlight = 0.0;
  /// air temperature: what unheated objects settle to [°C]
  double air_temperature_c = 15.0;
  /// smoke in the air for the colour camera (the `smoke` scenario); none by default
  SmokeSchedule smoke;

  std::uint32_t add_material(const Material& m) {
    materials.push_back(m);
    return static_cast<std::uint32_t>(materials.size() - 1);
  }
  /// An axis-aligned box from its min and max corners [m].
  void add_aabb(const Eigen::Vector3d& min_m, const Eigen::Vector3d& max_m, std::uint32_t material);
  /// A box rotated by `yaw_rad` about z (walls along a path, parked cars).
  void add_yawed(const Eigen::Vector3d& center_m, const Eigen::Vector3d& half_extent_m,
                 double yaw_rad, std::uint32_t material);
};

/// Where a ray met a box.
struct RayHit {
  /// distance along the (unit) ray [m]
  double t_m = 0.0;
  /// which box
  std::uint32_t box = 0;
  /// face: 0/1 = -x/+x, 2/3 = -y/+y, 4/5 = -z/+z in box axes
  std::uint8_t face = 0;
};

/// Slab test of a ray given in a box's own frame: origin `o` [m], unit direction `d` and its
/// reciprocal `inv_d` in box axes, against half extents `half_m` [m]. `t_max_m` bounds the
/// search. The entry hit (or the exit hit if the origin is inside the box), `box` left 0.
/// Inline: the BVH runs it for every box a ray reaches.
inline std::optional<RayHit> slab_hit(const std::array<double, 3>& o,
                                      const std::array<double, 3>& d,
                                      const std::array<double, 3>& inv_d,
                                      const std::array<double, 3>& half_m, double t_max_m) {
  double t_near = -std::numeric_limits<double>::infinity();
  double t_far = std::numeric_limits<double>::infinity();
  std::size_t near_axis = 0, far_axis = 0;
  for (std::size_t a = 0; a < 3; ++a) {
    const double h = half_m[a];
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < -h || o[a] > h) return std::nullopt;  // parallel and outside the slab
      continue;
    }
    double t0 = (-h - o[a]) * inv_d[a], t1 = (h - o[a]) * inv_d[a];
    if (t0 > t1) std::swap(t0, t1);
    if (t0 > t_near) {
      t_near = t0;
      near_axis = a;
    }
    if (t1 < t_far) {
      t_far = t1;
      far_axis = a;
    }
    if (t_near > t_far) return std::nullopt;
  }
  RayHit hit;
  if (t_near > 0.0) {
    if (t_near > t_max_m) return std::nullopt;
    hit.t_m = t_near;
    hit.face = static_cast<std::uint8_t>(2 * near_axis + (d[near_axis] < 0 ? 1 : 0));
  } else if (t_far > 0.0) {
    if (t_far > t_max_m) return std::nullopt;
    hit.t_m = t_far;  // inside the box (a tunnel's rock block around the sensor): its far wall
    hit.face = static_cast<std::uint8_t>(2 * far_axis + (d[far_axis] > 0 ? 1 : 0));
  } else {
    return std::nullopt;
  }
  return hit;
}

/// Ray-box intersection (slab test in the box frame). `t_max_m` bounds the search.
/// Returns the entry hit (or exit hit if the origin is inside the box).
std::optional<RayHit> intersect_box(const Box& box, const Eigen::Vector3d& origin_m,
                                    const Eigen::Vector3d& dir, double t_max_m);

/// Unit outward normal of a face, in map axes (inline: cameras ask per pixel).
inline Eigen::Vector3d face_normal_map(const Box& box, std::uint8_t face) {
  const int axis = face / 2;
  const double sign = (face % 2 == 1) ? 1.0 : -1.0;
  return sign * box.R_map_box.col(axis);
}

/// Texture coordinates of a map point on a face, in metres along the face's two axes.
Eigen::Vector2d face_uv_m(const Box& box, std::uint8_t face, const Eigen::Vector3d& p_map_m);

/// What one pixel sees of a face: the extent of its footprint along the face's u and v axes.
struct TextureFootprint {
  double u_m = 0;  ///< [m]
  double v_m = 0;  ///< [m]
};

/// The footprint on `face` of a pixel of angular pitch `pixel_angle_rad` whose ray (unit
/// `dir_map`) hits the face at range `range_m`: range x pitch, stretched by 1/cos of the
/// incidence along the axis the ray slants across (a wall seen at a grazing angle).
TextureFootprint pixel_footprint(const Box& box, std::uint8_t face, const Eigen::Vector3d& dir_map,
                                 double range_m, double pixel_angle_rad);

/// The texture averaged over a pixel's footprint (a box filter, analytic for the stripes, the
/// checkerboard and the mortar lines; value noise and brick colours fade to their mean as more
/// cells fall into the footprint). A camera that point-samples a pattern finer than its pixels
/// renders moiré that no real lens and sensor produce, and a tracker locks onto it; the real
/// camera integrates the light over the pixel. A zero footprint is the point sample.
/// 1 = mortar/dark line .. the pattern's range [0..1].
double texture_value(std::uint8_t texture, const Eigen::Vector2d& uv_m, std::uint32_t seed,
                     const TextureFootprint& footprint = {});

}  // namespace posed::sim
