// posectl inspect camera: lists V4L2 and GenICam (Aravis) cameras with their formats, or
// captures N frames of one camera to PNG files (16-bit formats kept as 16-bit PNG), with a
// progress line per frame and a summary.

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "core/payload_pool.hpp"
#include "drivers/camera/aravis_source.hpp"
#include "drivers/camera/frame_decoder.hpp"
#include "drivers/camera/pixel_formats.hpp"
#include "drivers/camera/v4l2_enumerate.hpp"
#include "drivers/camera/v4l2_source.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {
namespace {

namespace cam = drivers::camera;
namespace fs = std::filesystem;

constexpr std::string_view kAravisPrefix = "aravis:";

void print_v4l2(const std::string& dev_dir) {
  const auto nodes = cam::list_v4l2_nodes(dev_dir);
  std::printf("V4L2 devices (%zu nodes in %s):\n", nodes.size(), dev_dir.c_str());
  for (const auto& path : nodes) {
    cam::V4l2NodeInfo info;
    std::string error;
    if (!cam::query_v4l2_node(cam::system_v4l2_device(), path, info, error)) {
      std::printf("  %s: %s\n", path.c_str(), error.c_str());
      continue;
    }
    const char* kind = info.video_capture ? "video" : info.meta_capture ? "metadata" : "other";
    std::printf("  %s  %s (%s, %s) %s\n", path.c_str(), info.card.c_str(), info.driver.c_str(),
                info.bus_info.c_str(), kind);
    for (const auto& f : info.formats) {
      const auto known = cam::wire_format_from_fourcc(f.fourcc);
      std::printf("    %s %-28s%s\n", cam::fourcc_to_string(f.fourcc).c_str(),
                  f.description.c_str(),
                  known ? (" posed: " + std::string(cam::to_string(*known))).c_str()
                        : (info.meta_capture ? " posed: metadata" : " (not decoded by posed)"));
      for (const auto& s : f.sizes) {
        std::string rates;
        for (double r : s.rates_hz) {
          char buf[16];
          std::snprintf(buf, sizeof buf, " %g", r);
          rates += buf;
        }
        std::printf("      %ux%u%s%s%s\n", s.width, s.height, s.stepwise ? " (max, stepwise)" : "",
                    rates.empty() ? "" : " @", rates.empty() ? "" : (rates + " Hz").c_str());
      }
    }
  }
}

void print_aravis(bool include_fake) {
  const auto devices = cam::list_aravis_devices(true, include_fake);
  std::printf("GenICam devices (Aravis, %zu):\n", devices.size());
  for (const auto& d : devices) {
    std::printf("  aravis:%s  %s %s serial %s (%s %s)\n", d.id.c_str(), d.vendor.c_str(),
                d.model.c_str(), d.serial.c_str(), d.protocol.c_str(), d.address.c_str());
    std::string formats;
    for (const auto& f : d.pixel_formats) formats += " " + f;
    std::printf("    pixel formats:%s\n", formats.empty() ? " (could not open)" : formats.c_str());
  }
}

/// Writes one decoded image as PNG; 16-bit formats as 16-bit PNG.
bool write_png(const Image& img, const fs::path& path, std::string& error) {
  int type = CV_8UC1;
  switch (img.format) {
    case PixelFormat::kMono8:
      type = CV_8UC1;
      break;
    case PixelFormat::kMono16:
    case PixelFormat::kDepth16:
      type = CV_16UC1;
      break;
    case PixelFormat::kBgr8:
    case PixelFormat::kRgb8:
      type = CV_8UC3;
      break;
  }
  const cv::Mat view(static_cast<int>(img.height), static_cast<int>(img.width), type,
                     const_cast<std::byte*>(img.pixels.bytes().data()), img.stride);
  cv::Mat out = view;
  if (img.format == PixelFormat::kRgb8) cv::cvtColor(view, out, cv::COLOR_RGB2BGR);
  try {
    if (cv::imwrite(path.string(), out)) return true;
    error = "cannot write " + path.string();
  } catch (const cv::Exception& e) {
    error = "cannot write " + path.string() + ": " + e.what();
  }
  return false;
}

struct CaptureOptions {
  std::string device;
  int frames = 10;
  fs::path out_dir;
  std::string format = "yuyv";
  std::uint32_t width = 640, height = 480, fps = 30;
  int timeout_ms = 2000;
  bool aravis_fake = false;
};

int capture(const CaptureOptions& o) {
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec) {
    std::fprintf(stderr, "posectl inspect camera: cannot create %s: %s\n", o.out_dir.c_str(),
                 ec.message().c_str());
    return 1;
  }
  const bool aravis = o.device.rfind(kAravisPrefix, 0) == 0;
  std::unique_ptr<drivers::Source> source;
  cam::V4l2Source* v4l2 = nullptr;
  cam::AravisSource* genicam = nullptr;
  if (aravis) {
    if (o.aravis_fake) cam::list_aravis_devices(false, true);  // enables Aravis's Fake interface
    cam::AravisConfig cfg;
    cfg.camera_id = o.device.substr(kAravisPrefix.size());
    cfg.pixel_format = o.format == "y8" ? "Mono8" : o.format == "y16" ? "Mono16" : o.format;
    cfg.width = o.width;
    cfg.height = o.height;
    cfg.frame_rate_hz = o.fps;
    auto s = std::make_unique<cam::AravisSource>("inspect", cfg);
    genicam = s.get();
    source = std::move(s);
  } else {
    const auto wf = cam::wire_format_from_string(o.format);
    if (!wf) {
      std::fprintf(stderr, "posectl inspect camera: unknown --format '%s'\n", o.format.c_str());
      return 2;
    }
    cam::V4l2CaptureConfig cfg;
    cfg.device = o.device;
    cfg.format = *wf;
    cfg.width = o.width;
    cfg.height = o.height;
    cfg.fps = o.fps;
    auto s = std::make_unique<cam::V4l2Source>("inspect", cam::system_v4l2_device(), cfg);
    v4l2 = s.get();
    source = std::move(s);
  }
  std::string error;
  if (!source->open(error)) {
    std::fprintf(stderr, "posectl inspect camera: %s\n", error.c_str());
    return 1;
  }
  cam::FrameDecoderConfig dc;
  if (genicam != nullptr) {
    dc.format = genicam->format();
    dc.width = genicam->width();
    dc.height = genicam->height();
  } else {
    const auto& n = v4l2->capture().negotiated();
    dc.format = v4l2->capture().config().format;
    dc.width = n.width;
    dc.height = n.height;
    dc.stride_bytes = n.stride_bytes;
  }
  cam::FrameDecoder decoder(dc);
  PayloadPool pool(1, decoder.output_bytes());
  std::fprintf(stderr, "capturing %d frames of %s (%s %ux%u -> %.*s) into %s\n", o.frames,
               o.device.c_str(), std::string(cam::to_string(dc.format)).c_str(), dc.width,
               dc.height, static_cast<int>(to_string(decoder.output_format()).size()),
               to_string(decoder.output_format()).data(), o.out_dir.c_str());

  const auto start = std::chrono::steady_clock::now();
  int written = 0, timeouts = 0, partial = 0, failed = 0;
  std::uint64_t dropped = 0;
  while (written < o.frames && timeouts < 5) {
    drivers::RawChunk chunk;
    const auto s = source->read(chunk, Duration::from_ms(o.timeout_ms));
    if (s == drivers::ReadStatus::kTimeout || s == drivers::ReadStatus::kDeviceLost) {
      ++timeouts;
      std::fprintf(stderr, "  no frame within %d ms (%.*s)\n", o.timeout_ms,
                   static_cast<int>(drivers::to_string(s).size()), drivers::to_string(s).data());
      continue;
    }
    if (s != drivers::ReadStatus::kData) break;
    std::uint64_t sequence = 0;
    bool incomplete = false;
    if (genicam != nullptr) {
      sequence = genicam->last_frame().frame_id;
      dropped += genicam->last_frame().dropped_before;
      incomplete = genicam->last_frame().status != cam::AravisFrameStatus::kComplete;
    } else {
      sequence = v4l2->last_frame().sequence;
      dropped += v4l2->last_frame().dropped_before;
      incomplete = v4l2->last_frame().partial;
    }
    Image img;
    const auto ds = decoder.decode(chunk.bytes, sequence, pool, img);
    if (ds != cam::DecodeStatus::kOk && ds != cam::DecodeStatus::kPartial) {
      ++failed;
      std::fprintf(stderr, "  frame %llu: undecodable (%zu bytes)\n",
                   static_cast<unsigned long long>(sequence), chunk.bytes.size());
      continue;
    }
    partial += (incomplete || ds == cam::DecodeStatus::kPartial) ? 1 : 0;
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06d.png", written);
    if (!write_png(img, o.out_dir / name, error)) {
      std::fprintf(stderr, "posectl inspect camera: %s\n", error.c_str());
      return 1;
    }
    ++written;
    std::fprintf(stderr, "  [%d/%d] sequence %llu %zu B -> %s%s\n", written, o.frames,
                 static_cast<unsigned long long>(sequence), chunk.bytes.size(), name,
                 incomplete ? " (partial)" : "");
  }
  source->request_stop();
  drivers::RawChunk ignored;
  source->read(ignored, Duration::from_ms(1));
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf(
      "summary: device=%s written=%d/%d partial=%d dropped=%llu undecodable=%d "
      "timeouts=%d elapsed=%.2f s rate=%.1f Hz format=%.*s out=%s\n",
      o.device.c_str(), written, o.frames, partial, static_cast<unsigned long long>(dropped),
      failed, timeouts, elapsed, elapsed > 0 ? written / elapsed : 0.0,
      static_cast<int>(to_string(decoder.output_format()).size()),
      to_string(decoder.output_format()).data(), o.out_dir.c_str());
  return written == o.frames ? 0 : 1;
}

}  // namespace

int run_inspect_camera(int argc, char** argv) {
  CLI::App app{
      "Lists cameras, or captures frames of one to PNG.\n"
      "  posectl inspect camera --list\n"
      "      V4L2 nodes (/dev/video*: card, driver, formats, frame sizes and rates) and GenICam\n"
      "      cameras found by Aravis (GigE Vision, USB3 Vision) with their pixel formats.\n"
      "  posectl inspect camera DEVICE --frames N --out DIR [--format F --width W --height H]\n"
      "      DEVICE: /dev/videoN, a /dev/v4l/by-id link, serial:SERIAL[:INDEX], or aravis:ID.\n"
      "      Writes DIR/frame_000000.png ...: colour as 8-bit BGR PNG, Y8 as 8-bit grey, Y16 and\n"
      "      Z16 depth as 16-bit PNG (raw counts / device depth units, no scaling).",
      "posectl inspect camera"};
  bool list = false;
  CaptureOptions o;
  std::string dev_dir = "/dev", out;
  app.add_flag("--list", list, "list V4L2 and GenICam cameras with their formats");
  app.add_option("DEVICE", o.device, "camera to capture from");
  app.add_option("--frames", o.frames, "frames to capture")->check(CLI::Range(1, 100000));
  app.add_option("--out", out, "directory for the PNG files (created)");
  app.add_option("--format", o.format,
                 "wire format: yuyv, uyvy, rgb8, bgr8, mjpeg, z16, y8, y16 (aravis: y8/y16 or a "
                 "GenICam PixelFormat)")
      ->capture_default_str();
  app.add_option("--width", o.width, "frame width [px]")->capture_default_str();
  app.add_option("--height", o.height, "frame height [px]")->capture_default_str();
  app.add_option("--fps", o.fps, "frame rate [Hz]")->capture_default_str();
  app.add_option("--timeout-ms", o.timeout_ms, "wait per frame [ms]")->capture_default_str();
  app.add_option("--dev-dir", dev_dir, "where to look for video nodes")->capture_default_str();
  app.add_flag("--aravis-fake", o.aravis_fake,
               "also use Aravis's built-in Fake interface (a simulated camera, for trying this)");
  CLI11_PARSE(app, argc, argv);

  if (list) {
    print_v4l2(dev_dir);
    print_aravis(o.aravis_fake);
    return 0;
  }
  if (o.device.empty() || out.empty()) {
    std::fprintf(stderr, "posectl inspect camera: give --list, or DEVICE and --out DIR\n%s",
                 app.help().c_str());
    return 2;
  }
  o.out_dir = out;
  return capture(o);
}

}  // namespace posed::posectl
