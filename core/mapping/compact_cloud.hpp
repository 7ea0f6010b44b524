#pragma once
// A keyframe's cloud as the mapping layer keeps it for the whole run (docs/mapping.md, Memory):
// each coordinate a 16-bit count of 4 mm in the keyframe's own frame, 6 bytes a point where
// Eigen::Vector3f takes 12. Keyframe clouds are thinned to 0.3 m and kept within 60 m, so 4 mm
// (at most 2 mm off, a hundredth of a registration's residual) over +-131 m loses nothing a
// registration or a map file can tell; a campus drive keeps 10 M of these points. Header-only:
// the map files (drivers/recording) read and write it without the PCL-bound mapping library.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace posed::mapping {

class CompactCloud {
 public:
  /// the step of a stored coordinate [m]
  static constexpr float kResolutionM = 0.004f;
  /// the largest coordinate a point may have [m]
  static constexpr float kReachM = 32767 * kResolutionM;

  CompactCloud() = default;
  /// Every point of `points`, each within kReachM on every axis (fits()).
  explicit CompactCloud(std::span<const Eigen::Vector3f> points) { assign(points); }
  CompactCloud& operator=(std::span<const Eigen::Vector3f> points) {
    assign(points);
    return *this;
  }

  /// Whether `p` can be stored: finite and within kReachM on every axis.
  static bool fits(const Eigen::Vector3f& p) {
    return p.allFinite() && p.cwiseAbs().maxCoeff() <= kReachM;
  }
  /// Appends `p`, which must fit().
  void push_back(const Eigen::Vector3f& p) {
    points_.push_back({quantise(p.x()), quantise(p.y()), quantise(p.z())});
  }

  std::size_t size() const { return points_.size(); }
  /// The i-th point [m].
  Eigen::Vector3f operator[](std::size_t i) const {
    const std::array<std::int16_t, 3>& q = points_[i];
    return {q[0] * kResolutionM, q[1] * kResolutionM, q[2] * kResolutionM};
  }
  /// Every point, in the order stored [m].
  std::vector<Eigen::Vector3f> points() const {
    std::vector<Eigen::Vector3f> out;
    out.reserve(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i) out.push_back((*this)[i]);
    return out;
  }
  /// What the cloud holds [B].
  std::size_t bytes() const { return points_.capacity() * sizeof(points_[0]); }

  /// Iterates the points by value (for (const Eigen::Vector3f& p : cloud)).
  class const_iterator {
   public:
    const_iterator(const CompactCloud* cloud, std::size_t i) : cloud_(cloud), i_(i) {}
    Eigen::Vector3f operator*() const { return (*cloud_)[i_]; }
    const_iterator& operator++() {
      ++i_;
      return *this;
    }
    bool operator!=(const const_iterator& o) const { return i_ != o.i_; }
    bool operator==(const const_iterator& o) const { return i_ == o.i_; }

   private:
    const CompactCloud* cloud_;
    std::size_t i_;
  };
  const_iterator begin() const { return {this, 0}; }
  const_iterator end() const { return {this, points_.size()}; }

 private:
  static std::int16_t quantise(float v) {
    // Clamped, so a caller that skipped fits() gets a point at the edge, never a wrapped one.
    if (std::isnan(v)) return 0;
    return static_cast<std::int16_t>(std::clamp(std::round(v / kResolutionM), -32767.0f, 32767.0f));
  }
  void assign(std::span<const Eigen::Vector3f> points) {
    points_.clear();
    points_.reserve(points.size());
    for (const Eigen::Vector3f& p : points) push_back(p);
  }

  std::vector<std::array<std::int16_t, 3>> points_;
};

}  // namespace posed::mapping
