#pragma once
// The lower envelope of (device time x, apparent offset y = host arrival - device time) points.
// Transport delay only ever adds to y, so the true clock line lies below every point; the best
// samples (the least delayed) pin it. See clock_sync.hpp for why this estimator.
//
// Memory is bounded: x is cut into `bins` bins of `bin_width`, and each bin keeps only its
// minimum-y sample (a minimum-delay filter). The envelope's height at the centroid of a set of
// minima is the lower convex hull edge spanning that centroid: among all lines below every
// point, the one with the smallest total distance to the points (the linear programme of Moon,
// Skelly & Towsley, "Estimation and removal of clock skew from network delay measurements",
// 1999). The fitted line joins those heights for the older and the newer half of the window,
// so its slope rests on a baseline of half the window rather than on one hull edge.

#include <cstdint>
#include <vector>

#include "core/time.hpp"

namespace posed {

class LowerEnvelope {
 public:
  struct AddResult {
    /// the sample opened a new bin (older bins may have fallen out of the window)
    bool bin_opened = false;
    /// the sample became its bin's minimum
    bool new_minimum = false;
    /// the sample is older than the window and was not used
    bool too_old = false;
  };

  /// `bins` >= 2 bins of `bin_width` > 0 (smaller values are raised to these minimums).
  LowerEnvelope(Duration bin_width, std::uint32_t bins);

  /// Forgets every point; the next add() sets the origin.
  void clear();
  /// Adds one point: x = device stamp, y = host arrival - device stamp [ns].
  AddResult add(std::int64_t x_ns, std::int64_t y_ns);
  /// Recomputes the line from the current bin minima. While they span less than
  /// `min_slope_span` of device time the slope is not estimated (two close minima give a wild
  /// slope): the line keeps `prior_slope` and rests on the lowest point. Fitted slopes are
  /// clamped to +-max_abs_slope. Returns false when there are no points.
  bool fit(double prior_slope, Duration min_slope_span, double max_abs_slope);

  /// The fitted line on its own, to keep judging samples after clear() (stragglers) [ns].
  struct Line {
    std::int64_t origin_x = 0, origin_y = 0;
    double intercept = 0.0, slope = 0.0;
    std::int64_t y_at(std::int64_t x_ns) const;
    double residual(std::int64_t x_ns, std::int64_t y_ns) const;
  };
  Line line() const { return Line{origin_x_, origin_y_, intercept_, slope_}; }

  bool has_fit() const { return has_fit_; }
  /// The fitted y at device time x [ns], rounded.
  std::int64_t y_at(std::int64_t x_ns) const;
  /// The fitted y at x minus the observed y: how far a point lies above (>0) the line [ns].
  double residual(std::int64_t x_ns, std::int64_t y_ns) const;
  /// dy/dx of the fitted line (host = device * (1 + slope)) [1]
  double slope() const { return slope_; }
  /// mean height of the bin minima above the line at the last fit [ns]
  double mean_gap() const { return mean_gap_; }
  /// bins holding a point [1]
  std::uint32_t filled_bins() const { return filled_; }
  /// device-time span covered by the filled bins at the last fit [ns]
  double span_ns() const { return span_ns_; }

 private:
  struct Bin {
    std::int64_t index = 0;
    double x = 0.0;  ///< relative to origin_x_ [ns]
    double y = 0.0;  ///< relative to origin_y_ [ns]
    bool filled = false;
  };
  struct Point {
    double x, y;
  };
  /// The lower envelope's height at the centroid of a run of points, with its local slope.
  struct Centre {
    double x, y, slope;
  };
  Centre lower_centre(std::size_t begin, std::size_t end, double prior_slope);

  std::int64_t width_ns_;
  std::vector<Bin> bins_;
  std::vector<Point> points_;  ///< scratch for fit(), preallocated
  std::vector<Point> hull_;    ///< scratch for fit(), preallocated
  bool have_origin_ = false;
  std::int64_t origin_x_ = 0;
  std::int64_t origin_y_ = 0;
  std::int64_t newest_index_ = 0;
  std::uint32_t filled_ = 0;
  bool has_fit_ = false;
  /// line: y = intercept_ + slope_ * x, both relative to the origin
  double intercept_ = 0.0;
  double slope_ = 0.0;
  double mean_gap_ = 0.0;
  double span_ns_ = 0.0;
};

}  // namespace posed
