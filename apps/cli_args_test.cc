#include "apps/cli_args.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "slam/types/error.h"

namespace slamrig::app {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

struct Parsed {
  std::string log, out = "default";
  double resolution = 0.05;
  int particles = 30;
  bool lenient = false;
};

std::string Parse(const std::vector<std::string>& args, Parsed* p) {
  ArgParser parser("slamrig test", "LOG [options]", "A test command.");
  parser.AddPositional("LOG", "the log", &p->log);
  parser.AddOption("out", "DIR", "output", &p->out);
  parser.AddOption("resolution", "M", "cell size", &p->resolution);
  parser.AddOption("particles", "N", "count", &p->particles);
  parser.AddFlag("lenient", "skip bad lines", &p->lenient);
  try {
    parser.Parse(args);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ArgParserTest, ParsesBothOptionSpellingsFlagsAndPositionals) {
  Parsed p;
  EXPECT_EQ(Parse({"a.log", "--out", "d", "--resolution=0.1", "--lenient", "--particles", "7"}, &p),
            "");
  EXPECT_EQ(p.log, "a.log");
  EXPECT_EQ(p.out, "d");
  EXPECT_DOUBLE_EQ(p.resolution, 0.1);
  EXPECT_EQ(p.particles, 7);
  EXPECT_TRUE(p.lenient);
}

TEST(ArgParserTest, ErrorsNameCommandAndFlag) {
  Parsed p;
  EXPECT_THAT(Parse({"a.log", "--resolution", "abc"}, &p),
              HasSubstr("slamrig test: --resolution: expected a number, got 'abc'"));
  EXPECT_THAT(Parse({"a.log", "--particles", "2.5"}, &p),
              HasSubstr("--particles: expected an integer"));
  EXPECT_THAT(Parse({"a.log", "--colour", "red"}, &p), HasSubstr("unknown option '--colour'"));
  EXPECT_THAT(Parse({"a.log", "--out"}, &p), HasSubstr("--out needs a value (DIR)"));
  EXPECT_THAT(Parse({}, &p), HasSubstr("missing LOG"));
  EXPECT_THAT(Parse({"a.log", "b.log"}, &p), HasSubstr("unexpected argument 'b.log'"));
  EXPECT_THAT(Parse({"a.log", "--lenient=yes"}, &p), HasSubstr("--lenient takes no value"));
  EXPECT_THAT(Parse({"a.log", "--resolution", "nan"}, &p), HasSubstr("expected a number"));
}

TEST(ArgParserTest, RepeatedOptionsKeepEveryValueInOrder) {
  std::vector<std::string> sets;
  std::string log;
  ArgParser parser("slamrig test", "LOG", "A test command.");
  parser.AddPositional("LOG", "the log", &log);
  parser.AddRepeated("set", "KEY=VALUE", "override", &sets);
  parser.Parse({"--set", "a=1", "x.log", "--set=b.c=2"});
  EXPECT_EQ(sets, (std::vector<std::string>{"a=1", "b.c=2"}));
  EXPECT_EQ(log, "x.log");
}

TEST(ArgParserTest, HelpListsEverythingWithDefaults) {
  Parsed p;
  ArgParser parser("slamrig test", "LOG [options]", "A test command.");
  parser.AddPositional("LOG", "the log", &p.log);
  parser.AddOption("resolution", "M", "cell size", &p.resolution);
  const std::string help = parser.Help();
  EXPECT_THAT(help, HasSubstr("Usage: slamrig test LOG [options]"));
  EXPECT_THAT(help, HasSubstr("--resolution M"));
  EXPECT_THAT(help, HasSubstr("[default: 0.05]"));
  EXPECT_THAT(help, HasSubstr("-h, --help"));
}

// An option whose help states its default is not given a second, raw one ("[default: 0]" after
// "until the drive is done", or the robot's name twice).
TEST(ArgParserTest, HelpThatStatesItsDefaultIsNotRepeated) {
  Parsed p;
  ArgParser parser("slamrig test", "[options]", "A test command.");
  parser.AddOption("resolution", "M", "cell size (default: the map's own)", &p.resolution);
  const std::string help = parser.Help();
  EXPECT_THAT(help, HasSubstr("cell size (default: the map's own)\n"));
  EXPECT_THAT(help, Not(HasSubstr("[default: 0.05]")));
}

}  // namespace
}  // namespace slamrig::app
