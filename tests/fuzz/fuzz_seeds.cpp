// Writes the seed corpora of can_fuzz, realsense_fuzz and camera_frame_fuzz, with the builders
// the unit tests use, so the seeds follow the formats as the code does instead of being binary
// blobs in the repository. Where the shared real data has bytes of the format (the FLIR Duo Pro R
// 16-bit frame), the seeds are cut from it; the data is read, never copied into the repository.
// Usage: posed_fuzz_seeds can|realsense|camera_frame DIR [REALDATA_DIR]

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <string_view>
#include <vector>

#include "drivers/camera/mjpeg_decoder.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/common/wire_format.hpp"
#include "drivers/imu/can_frame.hpp"
#include "tests/unit/camera/d4xx_metadata_bytes.hpp"
#include "tests/unit/camera/fake_d4xx_usb.hpp"

namespace fs = std::filesystem;
namespace cam = posed::drivers::camera;

namespace {

bool write(const fs::path& path, const void* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out) std::fprintf(stderr, "posed_fuzz_seeds: cannot write %s\n", path.c_str());
  return static_cast<bool>(out);
}
bool write(const fs::path& path, const std::vector<std::byte>& v) {
  return write(path, v.data(), v.size());
}
bool write(const fs::path& path, std::string_view s) { return write(path, s.data(), s.size()); }

std::vector<std::byte> read_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  const std::string s((std::istreambuf_iterator<char>(in)), {});
  const auto* p = reinterpret_cast<const std::byte*>(s.data());
  return {p, p + s.size()};
}

// ---- can_fuzz: candump lines and kernel frames -----------------------------------------------

// The IMU of config/imu-can-example.yaml (counter 0x180, gyro 0x181, accel 0x182) for three
// samples, then one line of each other form the candump format has.
constexpr std::string_view kCandump =
    "(1700000000.000000) can0 180#40420F00\n"
    "(1700000000.000100) can0 181#0A00F6FF6400\n"
    "(1700000000.000200) can0 182#0500FBFFE803\n"
    "(1700000000.005000) can0 180#48550F00\n"
    "(1700000000.005100) can0 181#0B00F5FF6300\n"
    "(1700000000.005200) can0 182#0600FAFFE903\n"
    "(1700000000.010000) can0 180#50680F00\n"
    "(1700000000.010100) can0 181#0C00F4FF6200\n"
    "(1700000000.010200) can0 182#0700F9FFEA03\n"
    "(1700000000.011000) can1 12345678#DE.AD.BE.EF\n"
    "(1700000000.012000) can0 123##1DEADBEEF1122334455667788\n"
    "(1700000000.013000) can0 123#R\n"
    "(1700000000.014000) can0 123#R4\n"
    "(1700000000.015000) vcan0 20000004#0004000000000000\n"
    "(1700000000.016000) can0 123#1122334455667788_E\r\n";

bool can_seeds(const fs::path& dir) {
  namespace can = posed::drivers::can;
  bool ok = write(dir / "candump.log", kCandump);
  // The same frames as SocketCAN's read() returns them (16 or 72 bytes each), back to back.
  std::vector<std::byte> classic, fd;
  for (std::uint32_t id : {0x180u, 0x181u, 0x182u}) {
    can::CanFrame f;
    f.id = id;
    f.len = id == 0x180 ? 4 : 6;
    for (std::size_t i = 0; i < f.len; ++i) f.data[i] = static_cast<std::uint8_t>(id + i * 17);
    std::uint8_t k[can::kCanFdMtu];
    const std::size_t n = can::to_kernel_bytes(f, k);
    const auto* p = reinterpret_cast<const std::byte*>(k);
    classic.insert(classic.end(), p, p + n);
    f.fd = true;
    f.len = 12;
    const std::size_t m = can::to_kernel_bytes(f, k);
    fd.insert(fd.end(), p, p + m);
  }
  ok = write(dir / "kernel_frames.bin", classic) && ok;
  return write(dir / "kernel_fd_frames.bin", fd) && ok;
}

// ---- realsense_fuzz: UVC metadata, calibration tables, IIO layouts and records ---------------

bool realsense_seeds(const fs::path& dir) {
  bool ok = true;
  for (std::uint32_t extra : {0u, 8u}) {  // md_size with and without the md_header
    ok = write(dir / ("metadata_depth_" + std::to_string(extra) + ".bin"),
               posed::test::depth_metadata(extra).v) &&
         ok;
  }
  const posed::test::KnownD435iCalibration known;
  ok = write(dir / "table25.bin", posed::test::coefficients_table(known)) && ok;
  ok = write(dir / "table32.bin", posed::test::rgb_table(known)) && ok;
  // "<wire format>\n<records>": the D435i's accel (s16 in 32) and gyro (s32) layouts, 4 records.
  const std::pair<const char*, std::string> layouts[] = {
      {"accel", std::string(posed::drivers::wire::kIioAccel3d) +
                    ";in_accel_x:le:s16/32>>0;in_accel_y:le:s16/32>>0;in_accel_z:le:s16/32>>0;"
                    "in_timestamp:le:s64/64>>0"},
      {"gyro", std::string(posed::drivers::wire::kIioGyro3d) +
                   ";in_anglvel_x:le:s32/32>>0;in_anglvel_y:le:s32/32>>0;"
                   "in_anglvel_z:le:s32/32>>0;in_timestamp:le:s64/64>>0"}};
  for (const auto& [name, layout] : layouts) {
    std::string s = layout + "\n";
    for (int r = 0; r < 4; ++r) {
      const std::int32_t xyz[3] = {-1000 + r, 20 * r, 1000 - r};
      s.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
      s.append(4, '\0');  // padding to the timestamp's alignment
      const std::int64_t t = 1'700'000'000'000'000'000 + r * 5'000'000;
      s.append(reinterpret_cast<const char*>(&t), sizeof t);
    }
    ok = write(dir / (std::string("iio_") + name + ".bin"), s) && ok;
  }
  return ok;
}

// ---- camera_frame_fuzz: an 8-byte header (format, flags, width, height, stride), then bytes --

std::vector<std::byte> frame_header(cam::WireFormat format, std::uint8_t flags, std::uint16_t w,
                                    std::uint16_t h, std::uint16_t stride) {
  const std::uint8_t b[8] = {
      static_cast<std::uint8_t>(format), flags,
      static_cast<std::uint8_t>(w),      static_cast<std::uint8_t>(w >> 8),
      static_cast<std::uint8_t>(h),      static_cast<std::uint8_t>(h >> 8),
      static_cast<std::uint8_t>(stride), static_cast<std::uint8_t>(stride >> 8)};
  const auto* p = reinterpret_cast<const std::byte*>(b);
  return {p, p + 8};
}

bool frame_seed(const fs::path& path, cam::WireFormat format, std::uint8_t flags, std::uint16_t w,
                std::uint16_t h, std::uint16_t stride, std::span<const std::byte> pixels) {
  std::vector<std::byte> v = frame_header(format, flags, w, h, stride);
  v.insert(v.end(), pixels.begin(), pixels.end());
  return write(path, v);
}

bool camera_frame_seeds(const fs::path& dir, const fs::path& realdata) {
  using cam::WireFormat;
  // The real 640x512 little-endian 16-bit thermal frame, or a ramp when the data is absent.
  std::vector<std::byte> raw = read_file(realdata / "thermal_16bit/frame_000000_640x512_u16le.raw");
  const bool real = raw.size() == 640u * 512u * 2u;
  if (!real) {
    raw.resize(640u * 512u * 2u);
    for (std::size_t i = 0; i < raw.size(); ++i) raw[i] = static_cast<std::byte>(i * 7 / 3);
  }
  // 24 rows from the middle of the frame keep each seed near 30 kB (the fuzzer's max_len is 64k).
  const std::span<const std::byte> rows = std::span(raw).subspan(640u * 2u * 240u, 640u * 2u * 24u);
  bool ok = true;
  ok = frame_seed(dir / "y16_640x24", WireFormat::kY16, 0, 640, 24, 0, rows) && ok;
  ok = frame_seed(dir / "y16_agc_640x24", WireFormat::kY16, 1, 640, 24, 0, rows) && ok;
  ok = frame_seed(dir / "y16_agc_hist_320x24_stride", WireFormat::kY16, 1 | 4, 320, 24, 1280,
                  rows) &&
       ok;
  ok = frame_seed(dir / "z16_640x24", WireFormat::kZ16, 0, 640, 24, 0, rows) && ok;
  ok = frame_seed(dir / "y8_1280x24", WireFormat::kY8, 0, 1280, 24, 0, rows) && ok;
  ok = frame_seed(dir / "yuyv_640x24", WireFormat::kYuyv, 0, 640, 24, 0, rows) && ok;
  ok = frame_seed(dir / "uyvy_640x23_short", WireFormat::kUyvy, 0, 640, 24, 0,
                  rows.first(rows.size() - 700)) &&
       ok;
  ok = frame_seed(dir / "rgb8_400x24", WireFormat::kRgb8, 0, 400, 24, 1280, rows) && ok;
  ok = frame_seed(dir / "bgr8_424x24", WireFormat::kBgr8, 0, 424, 24, 0, rows) && ok;
  // MJPEG: the same rows stretched to 8 bits, compressed grey and colour (4:2:2) as UVC sends.
  std::vector<std::byte> grey(640u * 24u), bgr(640u * 24u * 3u);
  std::uint16_t lo = 0xFFFF, hi = 0;
  for (std::size_t i = 0; i < grey.size(); ++i) {
    const auto v = static_cast<std::uint16_t>(std::to_integer<unsigned>(rows[2 * i]) |
                                              std::to_integer<unsigned>(rows[2 * i + 1]) << 8);
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  for (std::size_t i = 0; i < grey.size(); ++i) {
    const auto v = static_cast<std::uint16_t>(std::to_integer<unsigned>(rows[2 * i]) |
                                              std::to_integer<unsigned>(rows[2 * i + 1]) << 8);
    grey[i] = static_cast<std::byte>(static_cast<unsigned>(v - lo) * 255u /
                                     static_cast<unsigned>(std::max(1, hi - lo)));
    for (std::size_t c = 0; c < 3; ++c) bgr[3 * i + c] = grey[i];
  }
  std::vector<std::byte> jpeg;
  if (cam::encode_jpeg(grey, 640, 24, posed::PixelFormat::kMono8, 85, jpeg)) {
    ok = frame_seed(dir / "mjpeg_grey_640x24", WireFormat::kMjpeg, 2, 640, 24, 0, jpeg) && ok;
  }
  if (cam::encode_jpeg(bgr, 640, 24, posed::PixelFormat::kBgr8, 85, jpeg)) {
    ok = frame_seed(dir / "mjpeg_bgr_640x24", WireFormat::kMjpeg, 0, 640, 24, 0, jpeg) && ok;
    ok = frame_seed(dir / "mjpeg_bgr_640x24_cut", WireFormat::kMjpeg, 0, 640, 24, 0,
                    std::span(jpeg).first(jpeg.size() / 2)) &&
         ok;
  }
  if (!real) std::fprintf(stderr, "posed_fuzz_seeds: no real thermal frame, seeded a ramp\n");
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4) {
    std::fprintf(stderr, "usage: posed_fuzz_seeds can|realsense|camera_frame DIR [REALDATA]\n");
    return 2;
  }
  const std::string_view kind = argv[1];
  const fs::path dir = argv[2];
  const fs::path realdata = argc == 4 ? fs::path(argv[3]) : fs::path();
  fs::create_directories(dir);
  bool ok = false;
  if (kind == "can") {
    ok = can_seeds(dir);
  } else if (kind == "realsense") {
    ok = realsense_seeds(dir);
  } else if (kind == "camera_frame") {
    ok = camera_frame_seeds(dir, realdata);
  } else {
    std::fprintf(stderr, "posed_fuzz_seeds: unknown kind '%s'\n", argv[1]);
    return 2;
  }
  return ok ? 0 : 1;
}
