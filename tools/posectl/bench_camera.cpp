// posectl bench camera: per-frame cost on one core of the camera decoders the daemon runs for
// every frame: D435i YUYV 640x480 -> BGR (target <= 1 ms), Z16 640x480 -> depth image in a pool
// buffer (<= 0.5 ms), PLUG 617 Y16 640x512 AGC (<= 1 ms; the real 16-bit thermal frame when the
// shared data is found, else a synthetic one), MJPEG 640x512 decode (reported); and the D435i's
// small per-sample parsers: UVC frame metadata (per frame) and IIO IMU records (per sample).

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "core/measurements.hpp"
#include "core/payload_pool.hpp"
#include "drivers/camera/d4xx_metadata.hpp"
#include "drivers/camera/mjpeg_decoder.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/camera/realsense_imu_decoder.hpp"
#include "drivers/camera/thermal_agc.hpp"
#include "tools/posectl/bench.hpp"

namespace posed::posectl {
namespace {

namespace cam = drivers::camera;
using Clock = std::chrono::steady_clock;

/// Runs `fn` for at least `min_s` and 50 frames; reports mean and 99th-percentile per frame.
template <class Fn>
void time_per_frame(std::string_view what, Fn&& fn, double min_s = 0.5) {
  std::vector<double> ms;
  ms.reserve(4096);
  const auto start = Clock::now();
  while (ms.size() < 50 || std::chrono::duration<double>(Clock::now() - start).count() < min_s) {
    const auto t0 = Clock::now();
    fn();
    ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  double sum = 0;
  for (double v : ms) sum += v;
  std::sort(ms.begin(), ms.end());
  const std::string base(what);
  report("camera", base + "_mean", sum / static_cast<double>(ms.size()), "ms/frame");
  report("camera", base + "_p99", ms[ms.size() * 99 / 100], "ms/frame");
}

/// Runs `fn` (which handles `items` items) repeatedly for `min_s`; reports the mean per item.
template <class Fn>
void time_per_item(std::string_view what, std::size_t items, Fn&& fn, double min_s = 0.3) {
  std::size_t calls = 0;
  const auto start = Clock::now();
  double elapsed = 0;
  while (calls < 10 || elapsed < min_s) {
    fn();
    ++calls;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  report("camera", std::string(what) + "_mean", elapsed * 1e9 / static_cast<double>(calls * items),
         "ns/item");
}

/// A D435i depth frame's metadata buffer: uvc_meta_buf, UVC header with PTS and SCR, then
/// md_capture_timing, md_capture_stats, md_depth_control, md_configuration.
std::vector<std::byte> depth_metadata_buffer() {
  std::vector<std::byte> b;
  auto u8 = [&](std::uint32_t v) { b.push_back(static_cast<std::byte>(v & 0xFF)); };
  auto u16 = [&](std::uint32_t v) { u8(v), u8(v >> 8); };
  auto u32 = [&](std::uint32_t v) { u16(v & 0xFFFF), u16(v >> 16); };
  u32(1'000'000), u32(0), u16(12);  // ns, sof
  const std::size_t len_at = b.size();
  u8(0), u8(0x8F);
  u32(123456), u32(654321), u16(77);  // PTS, SCR
  u32(cam::kMdCaptureTimingId), u32(32);
  for (std::uint32_t v : {1u, 0x3Fu, 42u, 123456u, 15000u, 8000u, 33333u, 900u}) u32(v);
  u32(0x00000003), u32(72);
  for (int i = 0; i < 18; ++i) u32(0);
  u32(cam::kMdDepthControlId), u32(52);
  for (int i = 0; i < 13; ++i) u32(static_cast<std::uint32_t>(i));
  u32(cam::kMdConfigurationId), u32(32);
  for (int i = 0; i < 8; ++i) u32(static_cast<std::uint32_t>(i));
  b[len_at] = static_cast<std::byte>(b.size() - cam::kUvcMetaBufPrefixBytes);
  return b;
}

std::vector<std::uint16_t> thermal_frame(bool& real) {
  namespace fs = std::filesystem;
  std::vector<fs::path> bases;
  if (const char* d = std::getenv("POSED_REALDATA")) bases.emplace_back(d);
  if (const char* s = std::getenv("POSED_SOURCE_DIR"))
    bases.push_back(fs::path(s) / "../shared/realdata");
  bases.push_back(fs::path(__FILE__).parent_path() / "../../../shared/realdata");
  for (const auto& b : bases) {
    std::ifstream in(b / "thermal_16bit/frame_000000_640x512_u16le.raw", std::ios::binary);
    std::vector<char> raw{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (raw.size() != 640u * 512u * 2u) continue;
    std::vector<std::uint16_t> px(640 * 512);
    for (std::size_t i = 0; i < px.size(); ++i) {
      px[i] = static_cast<std::uint16_t>(static_cast<std::uint8_t>(raw[2 * i]) |
                                         (static_cast<std::uint8_t>(raw[2 * i + 1]) << 8));
    }
    real = true;
    return px;
  }
  real = false;
  std::vector<std::uint16_t> px(640 * 512);
  for (std::size_t i = 0; i < px.size(); ++i) {
    px[i] = static_cast<std::uint16_t>(2600 + (i % 640) / 8 + ((i * 2654435761u) >> 28));
  }
  return px;
}

}  // namespace

int bench_camera() {
  PayloadPool pool(4, 640 * 512 * 3);

  {  // YUYV 640x480 -> BGR8 into a pool buffer
    constexpr std::uint32_t w = 640, h = 480;
    std::vector<std::byte> yuyv(w * h * 2);
    for (std::size_t i = 0; i < yuyv.size(); ++i)
      yuyv[i] = static_cast<std::byte>(i * 31 + i / 1280);
    auto lease = pool.acquire();
    time_per_frame("yuyv_640x480_to_bgr", [&] {
      cam::convert_frame({yuyv, w, h, 0, cam::WireFormat::kYuyv}, {lease.bytes(), 0});
    });
  }
  {  // Z16 640x480 -> depth Image (pool lease + geometry), as the D435i depth node delivers
    constexpr std::uint32_t w = 640, h = 480;
    std::vector<std::byte> z16(w * h * 2);
    for (std::size_t i = 0; i < z16.size(); ++i) z16[i] = static_cast<std::byte>(i * 7);
    time_per_frame("z16_640x480_to_depth", [&] {
      Image img;
      img.pixels = pool.acquire();
      cam::set_image_geometry(img, w, h, PixelFormat::kDepth16);
      cam::convert_frame({z16, w, h, 0, cam::WireFormat::kZ16}, {img.pixels.bytes(), img.stride});
    });
  }
  bool real = false;
  const auto y16 = thermal_frame(real);
  report("camera", "thermal_frame_is_real", real ? 1 : 0, "bool");
  std::vector<std::uint8_t> grey(640 * 512);
  for (auto mode : {cam::AgcMode::kPercentileStretch, cam::AgcMode::kHistogramEqualisation}) {
    cam::ThermalAgc agc({mode, 1.0, 99.0, 16});
    time_per_frame(std::string("y16_640x512_agc_") + std::string(cam::to_string(mode)),
                   [&] { agc.apply(y16.data(), 640 * 2, grey.data(), 640, 640, 512); });
  }
  {  // MJPEG 640x512 (the thermal camera's 8-bit stream): JPEG of the AGC'd frame, as BGR
    std::vector<std::byte> bgr(640 * 512 * 3);
    for (std::size_t i = 0; i < grey.size(); ++i) {
      bgr[3 * i] = bgr[3 * i + 1] = bgr[3 * i + 2] = static_cast<std::byte>(grey[i]);
    }
    std::vector<std::byte> jpeg;
    if (!cam::encode_jpeg(bgr, 640, 512, PixelFormat::kBgr8, 85, jpeg)) {
      std::fprintf(stderr, "posectl bench camera: JPEG encode failed\n");
      return 1;
    }
    report("camera", "mjpeg_640x512_size", static_cast<double>(jpeg.size()) / 1024.0, "KiB");
    cam::MjpegDecoder dec;
    auto lease = pool.acquire();
    time_per_frame("mjpeg_640x512_decode_bgr", [&] {
      dec.decode(jpeg, 640, 512, {lease.bytes(), 0}, PixelFormat::kBgr8);
    });
    time_per_frame("mjpeg_640x512_decode_mono8", [&] {
      dec.decode(jpeg, 640, 512, {lease.bytes(), 0}, PixelFormat::kMono8);
    });
    if (dec.counters().errors != 0) {
      std::fprintf(stderr, "posectl bench camera: MJPEG decode errors\n");
      return 1;
    }
  }
  {  // D435i UVC metadata, one buffer per frame
    const auto md = depth_metadata_buffer();
    cam::D4xxFrameMetadata out;
    std::uint64_t sink = 0;
    time_per_item("d4xx_metadata_parse", 1000, [&] {
      for (int i = 0; i < 1000; ++i) {
        cam::parse_d4xx_metadata(md, out);
        sink += out.frame_counter;
      }
    });
    if (sink == 0) return 1;
  }
  {  // D435i IIO records (24 B: x, y, z as le:s16/32, timestamp le:s64/64), a kernel buffer's
     // worth per read
    const char* wire =
        "iio-hid-gyro-3d;in_anglvel_x:le:s16/32>>0;in_anglvel_y:le:s16/32>>0;"
        "in_anglvel_z:le:s16/32>>0;in_timestamp:le:s64/64>>0";
    cam::RealsenseImuDecoder dec(wire);
    if (!dec.valid()) {
      std::fprintf(stderr, "posectl bench camera: %s\n", dec.error().c_str());
      return 1;
    }
    std::vector<std::byte> records(128 * 24);
    for (std::size_t i = 0; i < records.size(); ++i) records[i] = static_cast<std::byte>(i * 13);
    std::vector<cam::D4xxMotionSample> samples(128);
    time_per_item("iio_imu_decode", 128, [&] { dec.decode(records, samples); });
  }
  return 0;
}

}  // namespace posed::posectl
