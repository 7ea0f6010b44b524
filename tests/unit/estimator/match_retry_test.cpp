#include "core/estimator/match_retry.hpp"

#include <gtest/gtest.h>

namespace posed::estimator {
namespace {

TEST(MatchRetry, ARetryThatEndsWhereTheImuSaidIsUsedWithoutRestartingTheWindow) {
  // A turn close to a plain wall: too few correspondences at the IMU's prediction, enough a few
  // decimetres away, and the match ends near the prediction. Degenerate or not, the IMU is right.
  EXPECT_EQ(judge_match_retry(true, true, 0), MatchRetryVerdict::kUse);
  EXPECT_EQ(judge_match_retry(true, true, 3), MatchRetryVerdict::kUse);
}

TEST(MatchRetry, OnlyARetryThatPinsEveryDirectionMakesTheImuSuspect) {
  EXPECT_EQ(judge_match_retry(true, false, 0), MatchRetryVerdict::kImuSuspect);
  // A corridor's retry is the constant-velocity guess along the axis: it contradicts nothing.
  EXPECT_EQ(judge_match_retry(true, false, 1), MatchRetryVerdict::kReject);
  EXPECT_EQ(judge_match_retry(true, false, 3), MatchRetryVerdict::kReject);
}

TEST(MatchRetry, ARetryFarFromItsOwnGuessIsRejected) {
  EXPECT_EQ(judge_match_retry(false, true, 0), MatchRetryVerdict::kReject);
  EXPECT_EQ(judge_match_retry(false, false, 0), MatchRetryVerdict::kReject);
}

}  // namespace
}  // namespace posed::estimator
