#include "core/fusion/static_track_filter.hpp"

namespace posed::fusion {

void StaticTrackFilter::update(std::vector<vision::FrontendFeature>& features,
                               std::vector<std::uint64_t>& fixed) {
  next_.clear();
  std::size_t k = 0;
  const double threshold = config_.verified_displacement_px / config_.focal_px;
  for (vision::FrontendFeature& f : features) {
    while (k < tracks_.size() && tracks_[k].id < f.id) ++k;
    Track t{f.id, f.normalised, 0, false};
    if (k < tracks_.size() && tracks_[k].id == f.id) t = tracks_[k];
    ++t.frames;
    t.verified = t.verified || (f.normalised - t.first).norm() >= threshold;
    f.verified = t.verified;
    if (!t.verified && t.frames > config_.max_unverified_frames) {
      fixed.push_back(f.id);
      continue;
    }
    next_.push_back(t);
  }
  tracks_.swap(next_);
}

}  // namespace posed::fusion
