#include "slam/types/validation.h"

#include <gtest/gtest.h>

#include <limits>

#include "slam/types/check.h"

namespace slamrig {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

TEST(RulesTest, PassingValuesGiveNoErrors) {
  Rules rules;
  rules.Positive("a", 0.1).NonNegative("b", 0).AtLeast("c", 3, 3).InRange("d", 4096, 1, 4096);
  rules.InUnitInterval("e", 1.0).Fraction("f", 0.0).Require(true, "g", 1, "must hold");
  rules.Nested("h", {});
  EXPECT_TRUE(rules.errors().empty());
}

TEST(RulesTest, EachMessageNamesFieldValueAndRule) {
  Rules rules;
  rules.Positive("particles", 0).NonNegative("sigma_m", -0.5).AtLeast("beams", 2, 3);
  rules.InRange("threads", 0, 1, 4096).InUnitInterval("rate", 0.0).Fraction("p", 1.5);
  rules.Require(false, "max_m", 1.0, "must be > min_m");
  rules.Nested("pf", {"particles = 0; must be > 0"});
  const std::vector<std::string> expected = {
      "particles = 0; must be > 0",  "sigma_m = -0.5; must be >= 0",
      "beams = 2; must be >= 3",     "threads = 0; must be in [1, 4096]",
      "rate = 0; must be in (0, 1]", "p = 1.5; must be in [0, 1]",
      "max_m = 1; must be > min_m",  "pf.particles = 0; must be > 0"};
  EXPECT_EQ(rules.errors(), expected);
}

TEST(RulesTest, NanBreaksEveryNumericRule) {
  Rules rules;
  rules.Positive("a", kNan).NonNegative("b", kNan).AtLeast("c", kNan, 1.0);
  rules.InRange("d", kNan, 0.0, 1.0).InUnitInterval("e", kNan).Fraction("f", kNan);
  EXPECT_EQ(rules.errors().size(), 6u);
}

TEST(RulesTest, NestedUnderTheRootKeepsKeys) {
  Rules rules;
  rules.Nested("", {"seed = -1; must be >= 0"});
  EXPECT_EQ(rules.errors(), std::vector<std::string>{"seed = -1; must be >= 0"});
}

struct BrokenOptions {
  int particles = 0;
  std::vector<std::string> Validate() const {
    Rules rules;
    rules.Positive("particles", particles).Positive("threads", particles);
    return rules.errors();
  }
};

TEST(CheckValidDeathTest, AbortsNamingTheTypeAndTheFirstBrokenRule) {
  EXPECT_DEATH(SLAMRIG_CHECK_VALID(BrokenOptions{}, "BrokenOptions"),
               "invalid BrokenOptions: particles = 0; must be > 0");
  SLAMRIG_CHECK_VALID(BrokenOptions{.particles = 3}, "BrokenOptions");  // passes
}

}  // namespace
}  // namespace slamrig
