#include "drivers/recording/map_directory.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "drivers/recording/map_files.hpp"

namespace posed::drivers::recording {
namespace {

constexpr const char* kFormat = "posed-keyframe-map";
constexpr int kVersion = 1;
constexpr char kScanContextMagic[8] = {'P', 'O', 'S', 'E', 'D', 'S', 'C', '1'};

std::string join(const std::string& dir, const char* name) {
  return (std::filesystem::path(dir) / name).string();
}

bool write_cloud(const std::string& path, const mapping::KeyframeMap& map, std::string& error) {
  std::size_t n = 0;
  for (const mapping::MapKeyframe& kf : map.keyframes) {
    n += kf.points_base.size();
  }
  return write_atomically(path, error, [&](std::FILE* f) {
    if (std::fprintf(f,
                     "# .PCD v0.7 - Point Cloud Data file format\n"
                     "VERSION 0.7\nFIELDS x y z keyframe\nSIZE 4 4 4 4\nTYPE F F F U\n"
                     "COUNT 1 1 1 1\nWIDTH %zu\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS %zu\n"
                     "DATA binary\n",
                     n, n) < 0) {
      return false;
    }
    struct Point {
      float x, y, z;
      std::uint32_t keyframe;
    };
    static_assert(sizeof(Point) == 16);
    std::vector<Point> block;
    for (std::size_t i = 0; i < map.keyframes.size(); ++i) {
      const mapping::MapKeyframe& kf = map.keyframes[i];
      const Eigen::Isometry3f T_map_base = kf.T_map_base.cast<float>();
      block.clear();
      for (const Eigen::Vector3f& p : kf.points_base) {
        const Eigen::Vector3f q = T_map_base * p;
        block.push_back({q.x(), q.y(), q.z(), static_cast<std::uint32_t>(i)});
      }
      if (!block.empty() &&
          std::fwrite(block.data(), sizeof(Point), block.size(), f) != block.size()) {
        return false;
      }
    }
    return true;
  });
}

bool write_edges(const std::string& path, const mapping::KeyframeMap& map, std::string& error) {
  return write_atomically(path, error, [&](std::FILE* f) {
    if (std::fputs("# from to kind tx ty tz[m] qx qy qz qw sigma_translation[m] "
                   "sigma_rotation[rad] robust[sigma] (T_from_to: `to` in `from`)\n",
                   f) < 0) {
      return false;
    }
    for (const mapping::PoseGraphEdge& e : map.edges) {
      const Eigen::Vector3d t = e.T_from_to.translation();
      const Eigen::Quaterniond q = Eigen::Quaterniond(e.T_from_to.linear()).normalized();
      if (std::fprintf(f, "%zu %zu %s %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", e.from,
                       e.to, e.loop ? "loop" : "odometry", t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                       q.w(), e.sigma_translation_m, e.sigma_rotation_rad, e.robust_sigmas) < 0) {
        return false;
      }
    }
    return true;
  });
}

bool write_floats(std::FILE* f, const float* data, std::size_t n) {
  return n == 0 || std::fwrite(data, sizeof(float), n, f) == n;
}

bool write_scan_contexts(const std::string& path, const mapping::KeyframeMap& map,
                         std::string& error) {
  const auto rings = static_cast<std::uint32_t>(map.scan_context.rings);
  const auto sectors = static_cast<std::uint32_t>(map.scan_context.sectors);
  return write_atomically(path, error, [&](std::FILE* f) {
    const std::uint32_t header[3] = {rings, sectors,
                                     static_cast<std::uint32_t>(map.keyframes.size())};
    if (std::fwrite(kScanContextMagic, 1, 8, f) != 8 || std::fwrite(header, 4, 3, f) != 3) {
      return false;
    }
    // A keyframe without a descriptor (its place is mapped by an older one) is written as zeros:
    // no bin of a real descriptor is 0 everywhere, and the reader takes zeros back as none.
    const std::vector<float> none(std::size_t{rings} * sectors + rings + sectors, 0.0f);
    for (const mapping::MapKeyframe& kf : map.keyframes) {
      const mapping::ScanContext& sc = kf.context;
      if (sc.bins.size() == 0) {
        if (!write_floats(f, none.data(), none.size())) return false;
        continue;
      }
      if (sc.bins.rows() != static_cast<Eigen::Index>(rings) ||
          sc.bins.cols() != static_cast<Eigen::Index>(sectors)) {
        errno = EINVAL;
        return false;
      }
      // Column-major bins (Eigen's layout), then the ring key and the sector key.
      if (!write_floats(f, sc.bins.data(), rings * sectors) ||
          !write_floats(f, sc.ring_key.data(), rings) ||
          !write_floats(f, sc.sector_key.data(), sectors)) {
        return false;
      }
    }
    return true;
  });
}

bool write_manifest(const std::string& path, const mapping::KeyframeMap& map, std::string& error) {
  return write_atomically(path, error, [&](std::FILE* f) {
    const mapping::ScanContextConfig& sc = map.scan_context;
    return std::fprintf(
               f,
               "# posed keyframe map (docs/mapping.md, Map files)\n"
               "format: %s\nversion: %d\nframe: map\nkeyframes: %zu\nedges: %zu\nvoxel_m: %.9g\n"
               "max_range_m: %.9g\n"
               "scan_context:\n  rings: %d\n  sectors: %d\n  max_range_m: %.9g\n"
               "  height_offset_m: %.9g\n  shift_search: %d\n",
               kFormat, kVersion, map.keyframes.size(), map.edges.size(), map.voxel_m,
               map.max_range_m, sc.rings, sc.sectors, sc.max_range_m, sc.height_offset_m,
               sc.shift_search) >= 0;
  });
}

// --- reading ---

/// "FILE:LINE: what" (line 0: the file as a whole).
std::string at(const std::string& path, std::size_t line, const std::string& what) {
  return line == 0 ? path + ": " + what : path + ":" + std::to_string(line) + ": " + what;
}

template <class T>
bool manifest_value(const YAML::Node& node, const char* key, const std::string& path, T& out,
                    std::string& error) {
  const YAML::Node v = node[key];
  if (!v) {
    error = at(path, 0, std::string("missing key '") + key + "'");
    return false;
  }
  try {
    out = v.as<T>();
  } catch (const YAML::Exception&) {
    error = at(path, static_cast<std::size_t>(v.Mark().line + 1),
               std::string("key '") + key + "': not a valid value");
    return false;
  }
  return true;
}

bool read_manifest(const std::string& path, mapping::KeyframeMap& map, std::size_t& keyframes,
                   std::size_t& edges, std::string& error) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    error = at(path, 0, "cannot open (not a posed map directory, or an incomplete one)");
    return false;
  } catch (const YAML::Exception& e) {
    error = at(path, static_cast<std::size_t>(e.mark.line + 1), e.msg);
    return false;
  }
  std::string format;
  int version = 0;
  if (!manifest_value(root, "format", path, format, error) ||
      !manifest_value(root, "version", path, version, error)) {
    return false;
  }
  if (format != kFormat || version != kVersion) {
    error = at(path, 0,
               "format '" + format + "' version " + std::to_string(version) + ", expected '" +
                   kFormat + "' version " + std::to_string(kVersion));
    return false;
  }
  const YAML::Node sc = root["scan_context"];
  if (!sc || !sc.IsMap()) {
    error = at(path, 0, "missing key 'scan_context'");
    return false;
  }
  if (!manifest_value(root, "keyframes", path, keyframes, error) ||
      !manifest_value(root, "edges", path, edges, error) ||
      !manifest_value(root, "voxel_m", path, map.voxel_m, error) ||
      // Maps saved before stop 55 kept their clouds to 60 m and did not say so.
      (root["max_range_m"] && !manifest_value(root, "max_range_m", path, map.max_range_m, error)) ||
      !manifest_value(sc, "rings", path, map.scan_context.rings, error) ||
      !manifest_value(sc, "sectors", path, map.scan_context.sectors, error) ||
      !manifest_value(sc, "max_range_m", path, map.scan_context.max_range_m, error) ||
      !manifest_value(sc, "height_offset_m", path, map.scan_context.height_offset_m, error) ||
      !manifest_value(sc, "shift_search", path, map.scan_context.shift_search, error)) {
    return false;
  }
  if (map.scan_context.rings <= 0 || map.scan_context.sectors <= 0 ||
      map.scan_context.rings > 1000 || map.scan_context.sectors > 3600) {
    error = at(path, 0, "scan_context: rings and sectors must be in 1..1000 and 1..3600");
    return false;
  }
  if (!(map.max_range_m > 0 && map.max_range_m <= mapping::CompactCloud::kReachM)) {
    error = at(path, 0,
               "max_range_m must be above 0 and at most " +
                   std::to_string(static_cast<int>(mapping::CompactCloud::kReachM)) + " m");
    return false;
  }
  return true;
}

/// Lines that are neither blank nor comments, with their line numbers.
template <class OnLine>
bool for_each_line(const std::string& path, std::string& error, OnLine on_line) {
  std::ifstream in(path);
  if (!in) {
    error = at(path, 0, std::string("cannot open: ") + std::strerror(errno));
    return false;
  }
  std::string line;
  std::size_t number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') {
      continue;
    }
    if (!on_line(line, number)) {
      return false;
    }
  }
  return true;
}

/// "SECONDS.NANOSECONDS" as written by tum_line(), without going through a double.
bool parse_stamp(const std::string& text, std::int64_t& stamp_ns) {
  const bool negative = !text.empty() && text[0] == '-';
  const std::size_t dot = text.find('.');
  try {
    const std::string whole = text.substr(
        negative ? 1 : 0, dot == std::string::npos ? std::string::npos : dot - (negative ? 1 : 0));
    std::int64_t ns = std::stoll(whole) * 1'000'000'000;
    if (dot != std::string::npos) {
      std::string frac = text.substr(dot + 1);
      if (frac.empty() || frac.size() > 9 ||
          frac.find_first_not_of("0123456789") != std::string::npos) {
        return false;
      }
      frac.resize(9, '0');
      ns += std::stoll(frac);
    }
    stamp_ns = negative ? -ns : ns;
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

/// The pose of "tx ty tz qx qy qz qw" (as TUM writes it); false when it is not finite or its
/// quaternion is not unit.
bool pose_of(const double (&v)[7], Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(v[6], v[3], v[4], v[5]);
  const Eigen::Vector3d t(v[0], v[1], v[2]);
  if (!t.allFinite() || !std::isfinite(q.norm()) || std::abs(q.norm() - 1.0) > 1e-3) return false;
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return true;
}

bool read_keyframes(const std::string& path, mapping::KeyframeMap& map, std::string& error) {
  return for_each_line(path, error, [&](const std::string& line, std::size_t number) {
    std::istringstream fields(line);
    std::string stamp;
    double v[7];
    if (!(fields >> stamp >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5] >> v[6])) {
      error = at(path, number, "expected 8 fields (stamp tx ty tz qx qy qz qw)");
      return false;
    }
    mapping::MapKeyframe kf;
    if (!parse_stamp(stamp, kf.stamp_ns)) {
      error = at(path, number, "stamp '" + stamp + "' is not SECONDS.NANOSECONDS");
      return false;
    }
    if (!pose_of(v, kf.T_map_base)) {
      error = at(path, number, "pose is not finite or its quaternion not unit");
      return false;
    }
    map.keyframes.push_back(std::move(kf));
    return true;
  });
}

bool read_edges(const std::string& path, mapping::KeyframeMap& map, std::string& error) {
  return for_each_line(path, error, [&](const std::string& line, std::size_t number) {
    std::istringstream fields(line);
    mapping::PoseGraphEdge e;
    std::string kind;
    double v[7];
    if (!(fields >> e.from >> e.to >> kind >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5] >>
          v[6] >> e.sigma_translation_m >> e.sigma_rotation_rad >> e.robust_sigmas)) {
      error = at(path, number, "expected 13 fields (from to kind tx ty tz qx qy qz qw sigmas)");
      return false;
    }
    if (kind != "loop" && kind != "odometry") {
      error = at(path, number, "kind '" + kind + "' is neither loop nor odometry");
      return false;
    }
    if (e.from >= map.keyframes.size() || e.to >= map.keyframes.size()) {
      error = at(path, number, "joins a keyframe the map does not have");
      return false;
    }
    if (!pose_of(v, e.T_from_to)) {
      error = at(path, number, "pose is not finite or its quaternion not unit");
      return false;
    }
    e.loop = kind == "loop";
    map.edges.push_back(e);
    return true;
  });
}

bool read_scan_contexts(const std::string& path, mapping::KeyframeMap& map, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = at(path, 0, std::string("cannot open: ") + std::strerror(errno));
    return false;
  }
  char magic[8];
  std::uint32_t header[3];
  if (!in.read(magic, 8) || std::memcmp(magic, kScanContextMagic, 8) != 0 ||
      !in.read(reinterpret_cast<char*>(header), sizeof header)) {
    error = at(path, 0, "not a posed Scan Context file (bad magic or header at byte 0)");
    return false;
  }
  const auto rings = static_cast<Eigen::Index>(map.scan_context.rings);
  const auto sectors = static_cast<Eigen::Index>(map.scan_context.sectors);
  if (header[0] != static_cast<std::uint32_t>(rings) ||
      header[1] != static_cast<std::uint32_t>(sectors) || header[2] != map.keyframes.size()) {
    error = at(path, 0,
               "holds " + std::to_string(header[2]) + " descriptors of " +
                   std::to_string(header[0]) + " x " + std::to_string(header[1]) +
                   "; map.yaml and keyframes.tum say " + std::to_string(map.keyframes.size()) +
                   " of " + std::to_string(rings) + " x " + std::to_string(sectors));
    return false;
  }
  for (std::size_t i = 0; i < map.keyframes.size(); ++i) {
    mapping::ScanContext& sc = map.keyframes[i].context;
    sc.bins.resize(rings, sectors);
    sc.ring_key.resize(rings);
    sc.sector_key.resize(sectors);
    const auto offset = static_cast<long long>(in.tellg());
    if (!in.read(reinterpret_cast<char*>(sc.bins.data()),
                 static_cast<std::streamsize>(sizeof(float) * rings * sectors)) ||
        !in.read(reinterpret_cast<char*>(sc.ring_key.data()),
                 static_cast<std::streamsize>(sizeof(float) * rings)) ||
        !in.read(reinterpret_cast<char*>(sc.sector_key.data()),
                 static_cast<std::streamsize>(sizeof(float) * sectors))) {
      error = at(path, 0,
                 "truncated in descriptor " + std::to_string(i) + " (byte " +
                     std::to_string(offset) + ")");
      return false;
    }
    if (sc.bins.isZero(0) && sc.ring_key.isZero(0) && sc.sector_key.isZero(0)) {
      sc = mapping::ScanContext();  // written as none (write_scan_contexts)
    }
  }
  return true;
}

bool read_cloud(const std::string& path, mapping::KeyframeMap& map, std::string& error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = at(path, 0, std::string("cannot open: ") + std::strerror(errno));
    return false;
  }
  // The header: what posed writes (x y z keyframe, binary); other layouts are refused by name.
  std::string line;
  std::size_t number = 0;
  std::size_t points = 0;
  bool fields_ok = false;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') {
      continue;
    }
    std::istringstream words(line);
    std::string key;
    words >> key;
    if (key == "FIELDS") {
      fields_ok = line == "FIELDS x y z keyframe";
      if (!fields_ok) {
        error = at(path, number, "expected 'FIELDS x y z keyframe', found '" + line + "'");
        return false;
      }
    } else if (key == "SIZE" && line != "SIZE 4 4 4 4") {
      error = at(path, number, "expected 'SIZE 4 4 4 4'");
      return false;
    } else if (key == "TYPE" && line != "TYPE F F F U") {
      error = at(path, number, "expected 'TYPE F F F U'");
      return false;
    } else if (key == "POINTS") {
      if (!(words >> points)) {
        error = at(path, number, "POINTS: not a count");
        return false;
      }
    } else if (key == "DATA") {
      if (line != "DATA binary") {
        error = at(path, number, "expected 'DATA binary' (posed writes binary PCD)");
        return false;
      }
      break;
    }
  }
  if (!fields_ok || line != "DATA binary") {
    error = at(path, number, "header ends without FIELDS and DATA");
    return false;
  }
  std::vector<Eigen::Isometry3f> T_base_map;
  for (const mapping::MapKeyframe& kf : map.keyframes) {
    T_base_map.push_back(kf.T_map_base.inverse().cast<float>());
  }
  // The body in blocks: one read per block, not per point (a campus map is 10 M points).
  struct Point {
    float x, y, z;
    std::uint32_t keyframe;
  };
  static_assert(sizeof(Point) == 16);
  constexpr std::size_t kBlock = 65536;
  std::vector<Point> block(kBlock);
  for (std::size_t first = 0; first < points; first += kBlock) {
    const std::size_t n = std::min(kBlock, points - first);
    const auto offset = static_cast<long long>(in.tellg());
    in.read(reinterpret_cast<char*>(block.data()), static_cast<std::streamsize>(n * sizeof(Point)));
    const auto got = static_cast<std::size_t>(in.gcount()) / sizeof(Point);
    // "point N (byte B)": where in the file the k-th point of this block is.
    const auto point_at = [&](std::size_t k) {
      return "point " + std::to_string(first + k) + " (byte " +
             std::to_string(offset + static_cast<long long>(k * sizeof(Point))) + ")";
    };
    for (std::size_t k = 0; k < got; ++k) {
      const Point& p = block[k];
      if (p.keyframe >= map.keyframes.size()) {
        error = at(path, 0,
                   point_at(k) + " belongs to keyframe " + std::to_string(p.keyframe) + " of " +
                       std::to_string(map.keyframes.size()));
        return false;
      }
      const Eigen::Vector3f p_base = T_base_map[p.keyframe] * Eigen::Vector3f(p.x, p.y, p.z);
      if (!mapping::CompactCloud::fits(p_base)) {
        char where[160];
        std::snprintf(where, sizeof where, "(%.1f, %.1f, %.1f) m from it", p_base.x(), p_base.y(),
                      p_base.z());
        error = at(path, 0,
                   point_at(k) + " of keyframe " + std::to_string(p.keyframe) + " is " + where +
                       ": a keyframe keeps its points within " +
                       std::to_string(static_cast<int>(mapping::CompactCloud::kReachM)) +
                       " m of itself on every axis");
        return false;
      }
      map.keyframes[p.keyframe].points_base.push_back(p_base);
    }
    if (got < n) {
      error = at(path, 0,
                 "truncated at point " + std::to_string(first + got) + " of " +
                     std::to_string(points) + " (byte " +
                     std::to_string(offset + static_cast<long long>(got * sizeof(Point))) + ")");
      return false;
    }
  }
  return true;
}

}  // namespace

bool write_map_directory(const std::string& dir, const mapping::KeyframeMap& map,
                         std::string& error) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    error = "cannot create " + dir + ": " + ec.message();
    return false;
  }
  std::vector<StampedTransform> poses;
  poses.reserve(map.keyframes.size());
  for (const mapping::MapKeyframe& kf : map.keyframes) {
    poses.push_back({WallTime{kf.stamp_ns}, kf.T_map_base});
  }
  // The manifest last: a directory without it is incomplete.
  const std::string manifest = join(dir, "map.yaml");
  std::remove(manifest.c_str());
  return write_cloud(join(dir, "map.pcd"), map, error) &&
         write_tum(join(dir, "keyframes.tum"), poses, error) &&
         write_edges(join(dir, "edges.txt"), map, error) &&
         write_scan_contexts(join(dir, "scan_contexts.bin"), map, error) &&
         write_manifest(manifest, map, error);
}

bool read_map_directory(const std::string& dir, mapping::KeyframeMap& map, std::string& error) {
  map = mapping::KeyframeMap{};
  std::size_t keyframes = 0;
  std::size_t edges = 0;
  if (!read_manifest(join(dir, "map.yaml"), map, keyframes, edges, error) ||
      !read_keyframes(join(dir, "keyframes.tum"), map, error)) {
    return false;
  }
  if (map.keyframes.size() != keyframes) {
    error = at(join(dir, "keyframes.tum"), 0,
               "holds " + std::to_string(map.keyframes.size()) + " keyframes, map.yaml says " +
                   std::to_string(keyframes));
    return false;
  }
  if (!read_edges(join(dir, "edges.txt"), map, error)) {
    return false;
  }
  if (map.edges.size() != edges) {
    error = at(join(dir, "edges.txt"), 0,
               "holds " + std::to_string(map.edges.size()) + " edges, map.yaml says " +
                   std::to_string(edges));
    return false;
  }
  return read_scan_contexts(join(dir, "scan_contexts.bin"), map, error) &&
         read_cloud(join(dir, "map.pcd"), map, error);
}

}  // namespace posed::drivers::recording
