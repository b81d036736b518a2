#include "slam/types/validation.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

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

TEST(RulesTest, NumbersPrintShortestRoundTrip) {
  // Values and bounds alike: no "0.100000" and no digits lost (0.123456789 is not "0.123457").
  Rules rules;
  rules.AtLeast("a_m", 0.1, 0.15).InRange("b", 0.123456789, 0.2, 1.0);
  rules.Positive("c", -0.1f).Above("d", -1.0, -1.0).Require(false, "e", 1e-9, "must hold");
  const std::vector<std::string> expected = {
      "a_m = 0.1; must be >= 0.15", "b = 0.123456789; must be in [0.2, 1]", "c = -0.1; must be > 0",
      "d = -1; must be > -1", "e = 1e-09; must hold"};
  EXPECT_EQ(rules.errors(), expected);
  EXPECT_EQ(FormatValue(2.5), "2.5");
  EXPECT_EQ(FormatValue(0.1f), "0.1");
  EXPECT_EQ(FormatValue(std::int64_t{-12345678901}), "-12345678901");
  EXPECT_EQ(FormatValue(std::string("'x'")), "'x'");
}

TEST(RulesTest, IntervalEndsAreSaidAndKept) {
  Rules rules;
  rules.InRange("closed", 1.0, 0.0, 1.0).InRange("open_high", 0.0, 0.0, 1.0, Ends::kOpenHigh);
  rules.InRange("open_low", 1.0, 0.0, 1.0, Ends::kOpenLow)
      .InRange("open", 0.5, 0.0, 1.0, Ends::kOpen);
  EXPECT_TRUE(rules.errors().empty());
  rules.InRange("a", 1.0, 0.0, 1.0, Ends::kOpenHigh).InRange("b", 0.0, 0.0, 1.0, Ends::kOpenLow);
  rules.InRange("c", 0.0, 0.0, 1.0, Ends::kOpen).InRange("d", kNan, 0.0, 1.0, Ends::kOpen);
  rules.Above("e", kNan, 0.0);
  const std::vector<std::string> expected = {"a = 1; must be in [0, 1)", "b = 0; must be in (0, 1]",
                                             "c = 0; must be in (0, 1)",
                                             "d = nan; must be in (0, 1)", "e = nan; must be > 0"};
  EXPECT_EQ(rules.errors(), expected);
}

TEST(RulesTest, RequiredNamesTheMissingKey) {
  Rules rules;
  rules.Required(true, "module", "the module").Required(false, "class", "the estimator class");
  EXPECT_EQ(rules.errors(), std::vector<std::string>{"class: required (the estimator class)"});
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
