// The voxel map's flat index (VoxelIndex) against std::unordered_map under the churn a drive
// makes: voxels made as the robot goes, removed behind it, keys that collide in the table, and
// the table growing. Backward-shift deletion must leave every remaining key findable.

#include "core/lidar/voxel_index.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <unordered_map>
#include <vector>

namespace posed::lidar {
namespace {

TEST(VoxelIndex, AgreesWithAHashMapThroughInsertsAndRemovals) {
  VoxelIndex index(16);  // small, so it grows and its probe runs wrap around the table
  std::unordered_map<std::uint64_t, std::uint32_t> reference;
  std::mt19937_64 rng(7);
  // Keys from a narrow range collide often; the top bit stays clear, as key_of's do.
  std::uniform_int_distribution<std::uint64_t> key(0, 3000);
  std::vector<std::uint64_t> held;
  for (int step = 0; step < 200000; ++step) {
    const std::uint64_t k = key(rng) * 0x100000001ull;
    if (rng() % 3 != 0) {
      const auto [slot, made] = index.try_emplace(k);
      const auto [it, inserted] = reference.try_emplace(k, static_cast<std::uint32_t>(step));
      ASSERT_EQ(made, inserted) << "step " << step;
      if (made) {
        EXPECT_EQ(*slot, VoxelIndex::kNoSlot);
        *slot = static_cast<std::uint32_t>(step);
        held.push_back(k);
      } else {
        EXPECT_EQ(*slot, it->second);
      }
    } else {
      ASSERT_EQ(index.erase(k), reference.erase(k) == 1) << "step " << step;
    }
    ASSERT_EQ(index.size(), reference.size());
  }
  for (const std::uint64_t k : held) {
    const auto it = reference.find(k);
    EXPECT_EQ(index.find(k), it == reference.end() ? VoxelIndex::kNoSlot : it->second);
  }
  index.clear();
  EXPECT_EQ(index.size(), 0u);
  for (const auto& [k, slot] : reference) EXPECT_EQ(index.find(k), VoxelIndex::kNoSlot);
}

TEST(VoxelIndex, EveryKeyStaysFindableWhileOthersAreErased) {
  VoxelIndex index(4);
  std::vector<std::uint64_t> keys;
  for (std::uint64_t k = 1; k <= 6; ++k) {
    keys.push_back(k << 40);
    *index.try_emplace(keys.back()).first = static_cast<std::uint32_t>(k);
  }
  for (std::size_t i = 0; i < keys.size(); ++i) {
    ASSERT_TRUE(index.erase(keys[i]));
    EXPECT_FALSE(index.erase(keys[i]));
    EXPECT_EQ(index.find(keys[i]), VoxelIndex::kNoSlot);
    for (std::size_t j = i + 1; j < keys.size(); ++j) {
      EXPECT_EQ(index.find(keys[j]), static_cast<std::uint32_t>(j + 1)) << i << " " << j;
    }
  }
  EXPECT_EQ(index.size(), 0u);
}

}  // namespace
}  // namespace posed::lidar
