#include "tools/posectl/frontend_timeline.hpp"

#include <cmath>
#include <cstdlib>
#include <map>

#include "drivers/recording/mcap_reader.hpp"
#include "tools/sim/simulator.hpp"

namespace posed::posectl {
namespace {

bool parse_number(const std::map<std::string, std::string>& entries, const char* key, double& out) {
  const auto it = entries.find(key);
  if (it == entries.end()) return false;
  char* end = nullptr;
  out = std::strtod(it->second.c_str(), &end);
  return end != it->second.c_str();
}

constexpr const char* kPhaseNames[3] = {"before", "dense", "after"};
constexpr vision::FrontendMode kTimelineModes[3] = {
    vision::FrontendMode::kVisible, vision::FrontendMode::kThermal, vision::FrontendMode::kFused};

}  // namespace

std::optional<SimTiming> sim_timing(const std::string& path) {
  drivers::recording::McapReader reader;
  std::string error;
  if (!reader.open(path, error)) return std::nullopt;
  // posectl sim writes its record before the first message.
  drivers::recording::McapMessage first;
  reader.next(first);
  for (const auto& record : reader.metadata()) {
    if (record.name != sim::kSimMetadataName) continue;
    double epoch_ns = 0;
    if (!parse_number(record.entries, "host_epoch_ns", epoch_ns)) return std::nullopt;
    SimTiming timing;
    timing.host_epoch_ns = static_cast<std::int64_t>(epoch_ns);
    DegradedInterval d;
    if (parse_number(record.entries, "visible_degraded_from_s", d.from_s) &&
        parse_number(record.entries, "visible_degraded_to_s", d.to_s) &&
        parse_number(record.entries, "smoke_dense_from_s", d.dense_from_s) &&
        parse_number(record.entries, "smoke_dense_to_s", d.dense_to_s)) {
      timing.degraded = d;
    }
    return timing;
  }
  return std::nullopt;
}

FrontendTimeline::FrontendTimeline(std::string csv_path, std::optional<SimTiming> timing)
    : csv_path_(std::move(csv_path)), timing_(std::move(timing)) {}

FrontendTimeline::~FrontendTimeline() {
  if (csv_ != nullptr) std::fclose(csv_);
}

bool FrontendTimeline::open(std::string& error) {
  if (csv_path_.empty()) return true;
  csv_ = std::fopen(csv_path_.c_str(), "w");
  if (csv_ == nullptr) {
    error = "cannot write " + csv_path_;
    return false;
  }
  // t_s: true time since the start for a simulated recording, else the host clock.
  std::fprintf(csv_,
               "t_s,mode,status,carried_in,tracked,inliers,crowded,extracted,features,with_depth,"
               "confidence_visible,confidence_thermal,confidence_fused,"
               "gradient_visible,gradient_thermal,gradient_fused\n");
  return true;
}

void FrontendTimeline::on_frame(const vision::FrontendFrame& frame, const vision::VisualFrontend&) {
  const std::int64_t epoch_ns = timing_ ? timing_->host_epoch_ns : 0;
  const double t_s = static_cast<double>(frame.stamp.ns - epoch_ns) * 1e-9;
  const vision::ImageQuality* q[3] = {&frame.quality.visible, &frame.quality.thermal,
                                      &frame.quality.fused};
  if (csv_ != nullptr) {
    const vision::FrontendCounts& c = frame.counts;
    std::fprintf(csv_, "%.6f,%s,%s,%d,%d,%d,%d,%d,%d,%d", t_s,
                 std::string(vision::to_string(frame.mode)).c_str(),
                 std::string(vision::to_string(frame.status)).c_str(), c.previous, c.tracked,
                 c.ransac_inliers, c.crowded, c.extracted, c.features, c.depth_associated);
    for (const auto* s : q) std::fprintf(csv_, s->valid ? ",%.4f" : ",", s->confidence);
    for (const auto* s : q) std::fprintf(csv_, s->valid ? ",%.4f" : ",", s->gradient_metric);
    if (std::fprintf(csv_, "\n") < 0) write_failed_ = true;
  }
  if (!timing_ || !timing_->degraded) return;
  const DegradedInterval& d = *timing_->degraded;
  int phase = -1;
  if (t_s < d.from_s) phase = 0;
  if (t_s >= d.dense_from_s && t_s <= d.dense_to_s) phase = 1;
  if (t_s > d.to_s) phase = 2;
  if (phase < 0) return;  // the smoke thickening or clearing
  Sums& s = sums_[static_cast<std::size_t>(frame.mode)][static_cast<std::size_t>(phase)];
  ++s.frames;
  s.features += static_cast<std::uint64_t>(frame.counts.features);
  s.inliers += static_cast<std::uint64_t>(frame.counts.ransac_inliers);
  s.carried_in += static_cast<std::uint64_t>(frame.counts.previous);
  for (std::size_t k = 0; k < 3; ++k) {
    if (!q[k]->valid) continue;
    s.confidence[k] += q[k]->confidence;
    ++s.assessed[k];
  }
}

bool FrontendTimeline::finish() {
  if (csv_ != nullptr) {
    write_failed_ = std::fclose(csv_) != 0 || write_failed_;
    csv_ = nullptr;
  }
  if (timing_ && timing_->degraded) {
    const DegradedInterval& d = *timing_->degraded;
    std::printf(
        "\ncolour view degraded (posed.sim) from %.1f to %.1f s, dense from %.1f to %.1f s; "
        "before = [0, %.1f) s, dense = [%.1f, %.1f] s, after = (%.1f, end] s\n",
        d.from_s, d.to_s, d.dense_from_s, d.dense_to_s, d.from_s, d.dense_from_s, d.dense_to_s,
        d.to_s);
    std::printf("%-46s%12s%12s%12s\n", "", kPhaseNames[0], kPhaseNames[1], kPhaseNames[2]);
    const char* stream_names[3] = {"visible", "thermal", "fused"};
    for (const vision::FrontendMode mode : kTimelineModes) {
      const auto& phases = sums_[static_cast<std::size_t>(mode)];
      const std::string name(vision::to_string(mode));
      const auto row = [&](const std::string& label, auto cell) {
        std::printf("%-46s", label.c_str());
        for (const Sums& s : phases) {
          const double v = cell(s);
          if (std::isnan(v))
            std::printf("%12s", "-");
          else
            std::printf("%12.3f", v);
        }
        std::printf("\n");
      };
      row(name + ": frames [1]", [](const Sums& s) { return static_cast<double>(s.frames); });
      row(name + ": features output / frame [1]", [](const Sums& s) {
        return s.frames > 0 ? static_cast<double>(s.features) / static_cast<double>(s.frames) : NAN;
      });
      row(name + ": match success rate [0..1]", [](const Sums& s) {
        return s.carried_in > 0 ? static_cast<double>(s.inliers) / static_cast<double>(s.carried_in)
                                : NAN;
      });
      for (std::size_t k = 0; k < 3; ++k) {
        if (phases[0].assessed[k] + phases[1].assessed[k] + phases[2].assessed[k] == 0) continue;
        row(name + ": mean confidence, " + stream_names[k] + " [0..1]", [k](const Sums& s) {
          return s.assessed[k] > 0 ? s.confidence[k] / static_cast<double>(s.assessed[k]) : NAN;
        });
      }
    }
  }
  return !write_failed_;
}

}  // namespace posed::posectl
