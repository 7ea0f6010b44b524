// posectl inspect velodyne FILE.pcap: decodes a Velodyne capture (pcap or pcapng) and prints a
// summary (packets, model, return mode, rpm, scans, points per scan, gaps, malformed), or with
// --csv one row per returned point: packet,block,channel,x,y,z,intensity,ring,t_ns.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>

#include "drivers/recording/mapped_file.hpp"
#include "drivers/recording/pcap_parser.hpp"
#include "drivers/recording/pcap_udp.hpp"
#include "drivers/velodyne/calibration_loader.hpp"
#include "drivers/velodyne/device_clock.hpp"
#include "drivers/velodyne/packet_decoder.hpp"
#include "drivers/velodyne/position_packet.hpp"
#include "drivers/velodyne/scan_assembler.hpp"
#include "tools/posectl/commands.hpp"

namespace posed::posectl {

namespace rec = drivers::recording;
namespace vel = drivers::velodyne;

int run_inspect_velodyne(int argc, char** argv) {
  CLI::App app{
      "Decodes a Velodyne (VLP-32C, VLP-16, HDL-32E) capture, pcap or pcapng, and prints a "
      "summary:\npackets, model, return mode, rpm, scans, points per scan, gaps, malformed.\n"
      "With --csv: a header line, then one row per returned point\n"
      "  packet,block,channel,x,y,z,intensity,ring,t_ns\n"
      "(packet: 0-based index among datagrams to the data port, in file order; x,y,z [m] in the\n"
      "sensor frame, x forward, y left, z up; t_ns: firing time after the packet's first firing)\n"
      "and the summary on stderr.",
      "posectl inspect velodyne"};
  std::string path, calibration_path;
  bool csv = false;
  double cut_deg = 0.0;
  std::uint16_t data_port = 2368, position_port = 8308;
  app.add_option("FILE", path, "capture file (.pcap or .pcapng)")->required();
  app.add_option("--calibration", calibration_path,
                 "per-laser table: VeloView XML, ros-drivers or velodyne_decoder YAML "
                 "(default: the manual's table for the model in the file)");
  app.add_flag("--csv", csv, "print every returned point as CSV instead of the summary");
  app.add_option("--cut-azimuth", cut_deg, "scan boundary azimuth [deg], Velodyne convention")
      ->check(CLI::Range(0.0, 360.0));
  app.add_option("--data-port", data_port, "UDP port of data packets")->capture_default_str();
  app.add_option("--position-port", position_port, "UDP port of position packets")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  vel::Calibration calibration;
  std::string error;
  if (!calibration_path.empty() && !vel::load_calibration(calibration_path, calibration, error)) {
    std::fprintf(stderr, "posectl inspect velodyne: %s\n", error.c_str());
    return 1;
  }
  rec::MappedFile file;
  if (!file.open(path, error, "pcap")) {
    std::fprintf(stderr, "posectl inspect velodyne: %s\n", error.c_str());
    return 1;
  }
  rec::PcapParser parser(file.bytes());
  if (parser.open() != rec::PcapStatus::kOk) {
    std::fprintf(stderr, "posectl inspect velodyne: %s: %s\n", path.c_str(),
                 parser.describe_error().c_str());
    return 1;
  }

  vel::PacketDecoder decoder(std::move(calibration));
  // Big enough for a dual-return turn at 5 Hz; two buffers as scans are popped at once.
  PayloadPool pool(2, 240'000 * sizeof(LidarPoint));
  vel::ScanAssembler assembler(
      pool, {.cut_azimuth_cdeg = static_cast<std::uint32_t>(cut_deg * 100.0 + 0.5) % 36000});
  vel::HourUnwrapper clock;
  auto packet = std::make_unique<vel::DecodedPacket>();

  std::uint64_t data_packets = 0, position_packets = 0, position_bad = 0, other = 0,
                frame_errors = 0;
  vel::ReturnMode mode = vel::ReturnMode::kStrongest;
  double rpm_sum = 0.0;
  std::uint64_t rpm_n = 0;
  std::uint64_t scans = 0, complete_scans = 0, scan_points_sum = 0;
  std::uint32_t scan_points_min = UINT32_MAX, scan_points_max = 0;
  std::optional<vel::PositionPacket> last_position;
  const auto drain = [&] {
    vel::AssembledScan s;
    while (assembler.pop(s)) {
      ++scans;
      complete_scans += s.info.complete();
      scan_points_sum += s.scan.point_count;
      scan_points_min = std::min(scan_points_min, s.scan.point_count);
      scan_points_max = std::max(scan_points_max, s.scan.point_count);
    }
  };

  if (csv) std::printf("packet,block,channel,x,y,z,intensity,ring,t_ns\n");
  rec::PcapRecord record;
  rec::PcapStatus status;
  while ((status = parser.next(record)) == rec::PcapStatus::kOk) {
    rec::UdpDatagram d;
    const rec::FrameStatus f = rec::extract_udp(record.link_type, record.frame, d);
    if (f == rec::FrameStatus::kTruncated || f == rec::FrameStatus::kMalformed) {
      ++frame_errors;
      continue;
    }
    if (f != rec::FrameStatus::kOk) {
      ++other;
      continue;
    }
    if (d.dst_port == position_port) {
      vel::PositionPacket pos;
      const auto ps = vel::parse_position_packet(d.payload, pos);
      ++position_packets;
      if (ps == vel::PositionStatus::kOk || ps == vel::PositionStatus::kNoNmea) {
        last_position = pos;
      } else {
        ++position_bad;
      }
      continue;
    }
    if (d.dst_port != data_port) {
      ++other;
      continue;
    }
    const std::uint64_t index = data_packets++;
    if (decoder.decode(d.payload, *packet) != vel::DecodeStatus::kOk) continue;
    mode = packet->return_mode;
    if (packet->rpm > 0.f) {
      rpm_sum += packet->rpm;
      ++rpm_n;
    }
    if (csv) {
      for (std::uint32_t i = 0; i < packet->point_count; ++i) {
        const auto& p = packet->points[i];
        std::printf("%llu,%u,%u,%.4f,%.4f,%.4f,%u,%u,%d\n", static_cast<unsigned long long>(index),
                    p.block, p.channel, static_cast<double>(p.x_m), static_cast<double>(p.y_m),
                    static_cast<double>(p.z_m), p.intensity, p.ring, p.t_ns);
      }
    }
    assembler.add(*packet, clock.unwrap(packet->device_time_us));
    drain();
  }
  assembler.flush();
  drain();

  std::FILE* out = csv ? stderr : stdout;
  const auto& dc = decoder.counters();
  const auto& ac = assembler.counters();
  std::fprintf(out, "file: %s (%s)\n", path.c_str(),
               parser.format() == rec::CaptureFormat::kPcapng ? "pcapng" : "pcap");
  if (status != rec::PcapStatus::kEnd) {
    std::fprintf(out, "file error: %s\n", parser.describe_error().c_str());
  }
  std::fprintf(out, "packets: data=%llu position=%llu other=%llu damaged_frames=%llu\n",
               static_cast<unsigned long long>(data_packets),
               static_cast<unsigned long long>(position_packets),
               static_cast<unsigned long long>(other),
               static_cast<unsigned long long>(frame_errors));
  const std::string_view model = vel::to_string(decoder.product());
  const std::string_view mode_name = dc.packets_ok > 0 ? vel::to_string(mode) : "unknown";
  std::fprintf(
      out, "model: %.*s  return mode: %.*s  calibration: %s\n", static_cast<int>(model.size()),
      model.data(), static_cast<int>(mode_name.size()), mode_name.data(),
      decoder.calibration().source.empty() ? "none" : decoder.calibration().source.c_str());
  std::fprintf(out, "rpm: %.1f\n", rpm_n > 0 ? rpm_sum / static_cast<double>(rpm_n) : 0.0);
  std::fprintf(out, "scans: %llu (complete turns %llu, cut at %.2f deg)\n",
               static_cast<unsigned long long>(scans),
               static_cast<unsigned long long>(complete_scans), cut_deg);
  std::fprintf(out, "points per scan: min=%u mean=%.0f max=%u  points=%llu\n",
               scans > 0 ? scan_points_min : 0,
               scans > 0 ? static_cast<double>(scan_points_sum) / static_cast<double>(scans) : 0.0,
               scan_points_max, static_cast<unsigned long long>(dc.points));
  std::fprintf(out, "gaps: %llu (missing packets %llu, time jumps %llu)\n",
               static_cast<unsigned long long>(ac.gaps),
               static_cast<unsigned long long>(ac.missing_packets),
               static_cast<unsigned long long>(ac.time_jumps));
  std::fprintf(out,
               "malformed: %llu (wrong_size=%llu bad_block_flag=%llu bad_azimuth=%llu "
               "unknown_return_mode=%llu unknown_product=%llu model_mismatch=%llu) "
               "bad_position=%llu\n",
               static_cast<unsigned long long>(dc.malformed()),
               static_cast<unsigned long long>(dc.wrong_size),
               static_cast<unsigned long long>(dc.bad_block_flag),
               static_cast<unsigned long long>(dc.bad_azimuth),
               static_cast<unsigned long long>(dc.unknown_return_mode),
               static_cast<unsigned long long>(dc.unknown_product),
               static_cast<unsigned long long>(dc.model_mismatch),
               static_cast<unsigned long long>(position_bad));
  if (last_position) {
    const auto pps = vel::to_string(last_position->pps);
    std::fprintf(out, "last position packet: pps=%.*s", static_cast<int>(pps.size()), pps.data());
    if (last_position->gprmc) {
      const auto& g = *last_position->gprmc;
      std::fprintf(out, " gprmc=%04u-%02u-%02uT%02u:%02u:%02uZ %s", g.year, g.month, g.day, g.hour,
                   g.minute, g.second, g.valid ? "valid" : "no-fix");
    }
    std::fprintf(out, "\n");
  }
  return status == rec::PcapStatus::kEnd ? 0 : 1;
}

}  // namespace posed::posectl
