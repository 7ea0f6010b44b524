#pragma once
// A keyframe map on disk (posed --save-map DIR, posed --map DIR; docs/mapping.md, Map files):
//   map.yaml           what the directory holds: format version, counts, the descriptor's
//                      parameters (a query must be described alike); written last, so a directory
//                      without it is incomplete
//   map.pcd            every keyframe's cloud at its optimised pose, PCD v0.7 binary, fields
//                      x y z (float32, map frame [m]) and keyframe (uint32 index): PCL,
//                      CloudCompare and Open3D show it as the map
//   keyframes.tum      the keyframes' optimised poses (base_link in map), TUM, wall-clock stamps
//   edges.txt          the pose graph's edges: from to kind T_from_to sigmas
//   scan_contexts.bin  each keyframe's Scan Context (bins, ring key, sector key) as float32
// Every file is written to a temporary name and renamed into place.

#include <string>

#include "core/mapping/keyframe_map.hpp"

namespace posed::drivers::recording {

/// Creates `dir` if needed. False with `error` naming the file and the failing step.
bool write_map_directory(const std::string& dir, const mapping::KeyframeMap& map,
                         std::string& error);

/// False with `error` naming the file and the line, key or byte offset that is wrong.
bool read_map_directory(const std::string& dir, mapping::KeyframeMap& map, std::string& error);

}  // namespace posed::drivers::recording
