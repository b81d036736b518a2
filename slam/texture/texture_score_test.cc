#include "slam/texture/texture_score.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace slamrig::slam {
namespace {

TEST(TextureScoreTest, ErrorsAndCoverageOverObservedFloorCellsOnly) {
  cv::Mat3b truth(2, 3, cv::Vec3b(100, 100, 100));
  cv::Mat1b floor(2, 3, std::uint8_t{255});
  floor(1, 2) = 0;  // a wall cell: never scored
  cv::Mat3b colors = truth.clone();
  cv::Mat1b observed(2, 3, std::uint8_t{0});
  observed(0, 0) = observed(0, 1) = observed(1, 2) = 255;
  colors(0, 1) = cv::Vec3b(110, 90, 100);  // errors 10, 10, 0
  colors(1, 2) = cv::Vec3b(0, 0, 0);       // on the wall cell: ignored
  const TextureScore s = ScoreTexture(colors, observed, truth, floor);
  EXPECT_EQ(s.floor_cells, 5);
  EXPECT_EQ(s.observed_cells, 2);
  EXPECT_DOUBLE_EQ(s.coverage, 0.4);
  ASSERT_TRUE(s.mean_abs_error.has_value());
  EXPECT_DOUBLE_EQ(*s.mean_abs_error, 20.0 / 6.0);
  const double mse = 200.0 / 6.0;
  EXPECT_DOUBLE_EQ(*s.psnr_db, 10.0 * std::log10(255.0 * 255.0 / mse));
}

TEST(TextureScoreTest, NothingObservedHasNoColourErrorAndPerfectIsInfinite) {
  cv::Mat3b truth(2, 2, cv::Vec3b(1, 2, 3));
  cv::Mat1b floor(2, 2, std::uint8_t{255});
  cv::Mat1b none(2, 2, std::uint8_t{0});
  const TextureScore empty = ScoreTexture(truth, none, truth, floor);
  EXPECT_FALSE(empty.psnr_db.has_value());
  EXPECT_EQ(empty.coverage, 0.0);
  const TextureScore perfect = ScoreTexture(truth, floor, truth, floor);
  EXPECT_TRUE(std::isinf(*perfect.psnr_db));
  EXPECT_EQ(*perfect.mean_abs_error, 0.0);
  EXPECT_THROW(ScoreTexture(truth, cv::Mat1b(3, 2), truth, floor), std::invalid_argument);
}

}  // namespace
}  // namespace slamrig::slam
