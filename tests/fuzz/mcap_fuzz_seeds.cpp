// Writes the seed corpus of mcap_reader_fuzz with the real writer, so the seeds follow the
// writer as it changes instead of being binary blobs in the repository: small recordings with
// each compression, a schema, metadata, raw and CDR channels and several chunks, plus the same
// cut short and with no summary. Usage: mcap_fuzz_seeds DIR

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "drivers/recording/mcap_writer.hpp"
#include "drivers/recording/raw_channels.hpp"

namespace rec = posed::drivers::recording;

namespace {

bool write_seed(const std::string& path, rec::McapCompression compression, std::size_t chunk) {
  rec::McapWriterOptions o;
  o.compression = compression;
  o.chunk_size_bytes = chunk;
  o.fsync_on_close = false;
  rec::McapWriter w;
  std::string error;
  if (!w.open(path, o, error)) {
    std::fprintf(stderr, "mcap_fuzz_seeds: %s\n", error.c_str());
    return false;
  }
  w.write_metadata(rec::raw::kMetadataName, {{std::string(rec::raw::kHostToWallKey), "42"}});
  const std::string text = "geometry_msgs/Pose pose\n";
  const auto schema = w.add_schema("geometry_msgs/msg/PoseStamped", "ros2msg",
                                   {reinterpret_cast<const std::byte*>(text.data()), text.size()});
  const auto imu = w.add_channel(rec::raw::topic("imu", 0), rec::raw::kMessageEncoding, 0,
                                 {{std::string(rec::raw::kStreamKey), "imu"},
                                  {std::string(rec::raw::kWireFormatKey), "a9-serial"},
                                  {std::string(rec::raw::kSourceChannelKey), "0"}});
  const auto lidar = w.add_channel(rec::raw::topic("lidar", 1), rec::raw::kMessageEncoding, 0,
                                   {{std::string(rec::raw::kStreamKey), "lidar"},
                                    {std::string(rec::raw::kSourceChannelKey), "1"}});
  const auto pose = w.add_channel("/posed/pose", "cdr", schema, {});
  for (std::uint32_t i = 0; i < 24; ++i) {
    std::vector<std::byte> p(16 + (i * 7) % 40);
    for (std::size_t k = 0; k < p.size(); ++k) p[k] = static_cast<std::byte>((i + k * 3) & 0xFF);
    const std::uint64_t t = 1'000'000'000ull + i * 5'000'000ull;
    w.write_message(i % 3 == 0 ? lidar : (i % 3 == 1 ? imu : pose), i, t, t, p);
  }
  if (!w.close()) {
    std::fprintf(stderr, "mcap_fuzz_seeds: %s\n", w.error().c_str());
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: mcap_fuzz_seeds DIR\n");
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  const std::pair<const char*, rec::McapCompression> kinds[] = {
      {"none", rec::McapCompression::kNone},
      {"lz4", rec::McapCompression::kLz4},
      {"zstd", rec::McapCompression::kZstd}};
  for (const auto& [name, compression] : kinds) {
    const std::string path = (dir / (std::string("seed_") + name + ".mcap")).string();
    if (!write_seed(path, compression, 256)) return 1;
    // The same file cut inside its data, as after a power loss.
    std::ifstream in(path, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    std::ofstream((dir / (std::string("seed_") + name + "_cut.mcap")), std::ios::binary)
        .write(bytes.data(), static_cast<std::streamsize>(bytes.size() * 2 / 3));
  }
  // One chunk for everything: the summary-less shape of a writer that never closed.
  if (!write_seed((dir / "seed_one_chunk.mcap").string(), rec::McapCompression::kNone, 1 << 20)) {
    return 1;
  }
  return 0;
}
