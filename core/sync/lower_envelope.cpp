#include "core/sync/lower_envelope.hpp"

#include <algorithm>
#include <cmath>

namespace posed {
namespace {

std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

std::size_t slot_of(std::int64_t index, std::size_t n) {
  const auto m = static_cast<std::int64_t>(n);
  return static_cast<std::size_t>(((index % m) + m) % m);
}

}  // namespace

LowerEnvelope::LowerEnvelope(Duration bin_width, std::uint32_t bins)
    : width_ns_(std::max<std::int64_t>(bin_width.ns, 1)), bins_(std::max<std::uint32_t>(bins, 2)) {
  points_.reserve(bins_.size());
  hull_.reserve(bins_.size());
}

void LowerEnvelope::clear() {
  for (auto& b : bins_) b.filled = false;
  filled_ = 0;
  have_origin_ = false;
  has_fit_ = false;
  mean_gap_ = 0.0;
  span_ns_ = 0.0;
}

LowerEnvelope::AddResult LowerEnvelope::add(std::int64_t x_ns, std::int64_t y_ns) {
  AddResult r;
  if (!have_origin_) {
    // Relative coordinates keep the doubles small (device stamps may be ~1e18 ns).
    have_origin_ = true;
    origin_x_ = x_ns;
    origin_y_ = y_ns;
    newest_index_ = 0;
  }
  const std::int64_t index = floor_div(x_ns - origin_x_, width_ns_);
  const auto n = static_cast<std::int64_t>(bins_.size());
  if (index > newest_index_) {
    // Bins between the old newest and this one are now stale (dropped samples leave gaps).
    const std::int64_t first = std::max(newest_index_ + 1, index - n + 1);
    for (std::int64_t i = first; i <= index; ++i) {
      Bin& stale = bins_[slot_of(i, bins_.size())];
      if (stale.filled) --filled_;
      stale.filled = false;
    }
    newest_index_ = index;
    r.bin_opened = true;
  } else if (index <= newest_index_ - n) {
    r.too_old = true;
    return r;
  }
  Bin& b = bins_[slot_of(index, bins_.size())];
  const double x = static_cast<double>(x_ns - origin_x_);
  const double y = static_cast<double>(y_ns - origin_y_);
  // Slots of indices newer than the previous newest were emptied above, so a filled slot
  // always holds this very bin.
  if (!b.filled || y < b.y) {
    if (!b.filled) ++filled_;
    b = Bin{index, x, y, true};
    r.new_minimum = true;
  }
  return r;
}

LowerEnvelope::Centre LowerEnvelope::lower_centre(std::size_t begin, std::size_t end,
                                                  double prior_slope) {
  // Lower convex hull (Andrew's monotone chain); points are already sorted by x because bins
  // are visited in order and each holds one point.
  hull_.clear();
  double x_mean = 0.0;
  for (std::size_t i = begin; i < end; ++i) {
    const Point& p = points_[i];
    x_mean += p.x;
    while (hull_.size() >= 2) {
      const Point& o = hull_[hull_.size() - 2];
      const Point& a = hull_.back();
      const double cross = (a.x - o.x) * (p.y - o.y) - (a.y - o.y) * (p.x - o.x);
      if (cross > 0.0) break;  // a counter-clockwise turn keeps `a` on the lower hull
      hull_.pop_back();
    }
    hull_.push_back(p);
  }
  x_mean /= static_cast<double>(end - begin);
  if (hull_.size() == 1) return Centre{hull_[0].x, hull_[0].y, prior_slope};
  // The hull edge above the centroid maximises the line's height there, i.e. minimises the
  // summed distances to all points while staying below every one of them.
  std::size_t e = 0;
  while (e + 2 < hull_.size() && hull_[e + 1].x < x_mean) ++e;
  const Point& a = hull_[e];
  const Point& b = hull_[e + 1];
  const double slope = (b.y - a.y) / (b.x - a.x);
  return Centre{x_mean, a.y + slope * (x_mean - a.x), slope};
}

bool LowerEnvelope::fit(double prior_slope, Duration min_slope_span, double max_abs_slope) {
  points_.clear();
  const auto n = static_cast<std::int64_t>(bins_.size());
  for (std::int64_t i = newest_index_ - n + 1; i <= newest_index_; ++i) {
    const Bin& b = bins_[slot_of(i, bins_.size())];
    if (b.filled && b.index == i) points_.push_back({b.x, b.y});
  }
  if (points_.empty()) return false;

  const double span = points_.back().x - points_.front().x;
  if (points_.size() < 4 || span < static_cast<double>(min_slope_span.ns)) {
    // Too short a baseline for a slope: keep the prior and put the line as high as it can go
    // while staying below every point.
    slope_ = prior_slope;
    intercept_ = points_.front().y - slope_ * points_.front().x;
    for (const Point& p : points_) intercept_ = std::min(intercept_, p.y - slope_ * p.x);
  } else {
    // Drift from two half-windows: the envelope height at the centroid of the older and of the
    // newer half of the minima, each the linear-programme optimum of its half (pinned by many
    // samples, so good to a fraction of the best delays). Their distance is half the window,
    // which keeps the slope error small; a single hull edge can be short and badly sloped.
    // The line passes through the newer centre, so stamps near "now" extrapolate least.
    const std::size_t half = points_.size() / 2;
    const Centre older = lower_centre(0, half, prior_slope);
    const Centre newer = lower_centre(half, points_.size(), prior_slope);
    slope_ = std::clamp((newer.y - older.y) / (newer.x - older.x), -max_abs_slope, max_abs_slope);
    intercept_ = newer.y - slope_ * newer.x;
  }
  double gap = 0.0;
  for (const Point& p : points_) gap += p.y - (intercept_ + slope_ * p.x);
  mean_gap_ = gap / static_cast<double>(points_.size());
  span_ns_ = span;
  has_fit_ = true;
  return true;
}

std::int64_t LowerEnvelope::Line::y_at(std::int64_t x_ns) const {
  const double x = static_cast<double>(x_ns - origin_x);
  return origin_y + std::llround(intercept + slope * x);
}

double LowerEnvelope::Line::residual(std::int64_t x_ns, std::int64_t y_ns) const {
  const double x = static_cast<double>(x_ns - origin_x);
  const double y = static_cast<double>(y_ns - origin_y);
  return y - (intercept + slope * x);
}

std::int64_t LowerEnvelope::y_at(std::int64_t x_ns) const { return line().y_at(x_ns); }

double LowerEnvelope::residual(std::int64_t x_ns, std::int64_t y_ns) const {
  return line().residual(x_ns, y_ns);
}

}  // namespace posed
