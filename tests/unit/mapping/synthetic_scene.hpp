#pragma once
// Point clouds sampled from boxes, for the mapping tests that need exact geometry: a furnished
// room (every direction pinned) and a plain corridor (nothing along its axis).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

namespace posed::test {

struct Box {
  Eigen::Vector3f lo, hi;
};

/// Points on the faces of `boxes` at roughly `spacing_m`, seen from nowhere in particular (no
/// occlusion): every face is sampled.
inline std::vector<Eigen::Vector3f> sample_boxes(const std::vector<Box>& boxes, float spacing_m) {
  std::vector<Eigen::Vector3f> out;
  for (const Box& b : boxes) {
    const Eigen::Vector3f size = b.hi - b.lo;
    for (int axis = 0; axis < 3; ++axis) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      for (float side : {b.lo[axis], b.hi[axis]}) {
        for (float a = 0; a <= size[u]; a += spacing_m) {
          for (float c = 0; c <= size[v]; c += spacing_m) {
            Eigen::Vector3f p;
            p[axis] = side;
            p[u] = b.lo[u] + a;
            p[v] = b.lo[v] + c;
            out.push_back(p);
          }
        }
      }
    }
  }
  return out;
}

/// A 12 x 9 x 3 m room with furniture of different sizes.
inline std::vector<Box> furnished_room() {
  return {{{-6, -4.5f, -0.05f}, {6, 4.5f, 0}},  // floor
          {{-6, -4.5f, 3}, {6, 4.5f, 3.05f}},   // ceiling
          {{-6.05f, -4.5f, 0}, {-6, 4.5f, 3}},  // walls
          {{6, -4.5f, 0}, {6.05f, 4.5f, 3}},    {{-6, -4.55f, 0}, {6, -4.5f, 3}},
          {{-6, 4.5f, 0}, {6, 4.55f, 3}},       {{-4, -3, 0}, {-2.5f, -1, 0.8f}},  // a table
          {{1, 2, 0}, {1.6f, 4.5f, 2.1f}},                                         // a cupboard
          {{3, -3.5f, 0}, {4.2f, -2.8f, 1.2f}},                                    // a cabinet
          {{-1, 0.5f, 0}, {-0.6f, 0.9f, 1.8f}}};                                   // a pillar
}

/// A plain corridor 2.4 m wide, 2.6 m high, `length_m` long along x.
inline std::vector<Box> plain_corridor(float length_m) {
  const float h = length_m / 2;
  return {{{-h, -1.2f, -0.05f}, {h, 1.2f, 0}},
          {{-h, -1.2f, 2.6f}, {h, 1.2f, 2.65f}},
          {{-h, -1.25f, 0}, {h, -1.2f, 2.6f}},
          {{-h, 1.2f, 0}, {h, 1.25f, 2.6f}}};
}

/// `points` moved by `T` with Gaussian noise of `sigma_m` per axis.
inline std::vector<Eigen::Vector3f> transformed(const std::vector<Eigen::Vector3f>& points,
                                                const Eigen::Isometry3d& T, double sigma_m,
                                                unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, static_cast<float>(sigma_m));
  const Eigen::Isometry3f Tf = T.cast<float>();
  std::vector<Eigen::Vector3f> out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    out.push_back(Tf * p + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
  }
  return out;
}

inline Eigen::Isometry3d pose(double x, double y, double z, double yaw_rad) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

}  // namespace posed::test
