#include "scenarios/slurm_sweep.h"

#include <gtest/gtest.h>

namespace slamrig::scenario {
namespace {

TEST(SlurmSweepTest, ArrayIndicesCompressRunsOfConsecutiveRows) {
  EXPECT_EQ(SlurmArrayIndices({}), "");
  EXPECT_EQ(SlurmArrayIndices({4}), "4");
  EXPECT_EQ(SlurmArrayIndices({0, 1, 2, 5, 7, 8}), "0-2,5,7-8");
  EXPECT_EQ(SlurmArrayIndices({3, 5, 7}), "3,5,7");
  // Every index of a long list is covered exactly once: expand the text and compare.
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < 200; ++i) {
    if (i % 7 != 3 && i % 11 != 0) rows.push_back(i);
  }
  std::vector<std::size_t> expanded;
  const std::string text = SlurmArrayIndices(rows);
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t comma = std::min(text.find(',', at), text.size());
    const std::string part = text.substr(at, comma - at);
    const std::size_t dash = part.find('-');
    const std::size_t first = std::stoul(part.substr(0, dash));
    const std::size_t last = dash == std::string::npos ? first : std::stoul(part.substr(dash + 1));
    for (std::size_t i = first; i <= last; ++i) expanded.push_back(i);
    at = comma + 1;
  }
  EXPECT_EQ(expanded, rows);
}

}  // namespace
}  // namespace slamrig::scenario
