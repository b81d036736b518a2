#include "slam/config/yaml_node.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

namespace slamrig {
namespace {

using ::testing::HasSubstr;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(YamlNodeTest, ReadsValuesAndKeepsDefaults) {
  const auto root = YamlNode::LoadString("a: 1.5\nb: {c: 3, d: [1, 2]}\nname: x\n", "t.yaml");
  double a = 0, missing = 7;
  root.Read("a", &a);
  root.Read("zzz", &missing);
  EXPECT_EQ(a, 1.5);
  EXPECT_EQ(missing, 7);
  const auto b = root.Required("b");
  EXPECT_EQ(b.Get<int>("c"), 3);
  const auto d = b.Required("d").Elements();
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[1].As<int>(), 2);
  EXPECT_EQ(root.Get<std::string>("name"), "x");
  root.CheckAllKeysUsed();
}

TEST(YamlNodeTest, UnknownKeyNamesFileLineAndPath) {
  const auto root = YamlNode::LoadString("robot:\n  radius_m: 1\n  raduis: 2\n", "w.yaml");
  double r = 0;
  root.Required("robot").Read("radius_m", &r);
  EXPECT_EQ(ErrorOf([&] { root.CheckAllKeysUsed(); }), "w.yaml:3:3: robot.raduis: unknown key");
}

TEST(YamlNodeTest, WrongTypeNamesLocationAndText) {
  const auto root = YamlNode::LoadString("list:\n  - {v: abc}\n", "w.yaml");
  const auto e = ErrorOf([&] { root.Required("list").Elements()[0].Get<double>("v"); });
  EXPECT_THAT(e, HasSubstr("w.yaml:2:9: list[0].v: expected a number, got 'abc'"));
  EXPECT_THAT(ErrorOf([&] { root.Get<int>("list"); }),
              HasSubstr("list: expected an integer, got a list"));
}

TEST(YamlNodeTest, MissingRequiredKeyAndSyntaxErrors) {
  const auto root = YamlNode::LoadString("a: 1\n", "m.yaml");
  EXPECT_THAT(ErrorOf([&] { root.Get<double>("b"); }), HasSubstr("missing required key 'b'"));
  EXPECT_THAT(ErrorOf([] { YamlNode::LoadString("a: [1, 2\n", "s.yaml"); }), HasSubstr("s.yaml:"));
  EXPECT_THAT(ErrorOf([] { YamlNode::LoadFile("/nonexistent/x.yaml"); }),
              HasSubstr("/nonexistent/x.yaml: cannot open file"));
}

TEST(YamlNodeTest, RejectsNonFiniteNumbersAndFractionalIntegers) {
  const auto root = YamlNode::LoadString("a: .nan\nb: 1.5\n", "n.yaml");
  EXPECT_THAT(ErrorOf([&] { root.Get<double>("a"); }), HasSubstr("finite"));
  EXPECT_THAT(ErrorOf([&] { root.Get<int>("b"); }), HasSubstr("expected an integer"));
}

TEST(YamlNodeTest, OverridesSetNestedKeysAndListElements) {
  auto root =
      YamlNode::LoadString("slam:\n  pf: {num_particles: 30}\nlist: [1, 2, 3]\nx: 1\n", "o.yaml");
  root.Override("slam.pf.num_particles", "100");
  root.Override("slam.pf.new_key", "true");
  root.Override("list[1]", "20");
  root.Override("brand.new.path", "[1, 2]");
  EXPECT_EQ(root.Required("slam").Required("pf").Get<int>("num_particles"), 100);
  EXPECT_TRUE(root.Required("slam").Required("pf").Get<bool>("new_key"));
  EXPECT_EQ(root.Required("list").Elements()[1].As<int>(), 20);
  EXPECT_EQ(root.Required("brand").Required("new").Required("path").Elements().size(), 2u);
  EXPECT_THAT(ErrorOf([&] { root.Override("x.y", "1"); }), HasSubstr("not a map"));
  EXPECT_THAT(ErrorOf([&] { root.Override("list[7]", "1"); }), HasSubstr("no list element [7]"));
}

// Errors about what an override set, or about a map it created on the way, name the override.
TEST(YamlNodeTest, ErrorsAboutOverriddenValuesNameTheOverride) {
  YamlNode root = YamlNode::LoadString("a: {b: 1}\n", "o.yaml");
  root.Override("a.b", "x", "--set a.b=x");
  root.Override("c.d", "2", "--set c.d=2");
  EXPECT_EQ(ErrorOf([&] { root.Required("a").Get<int>("b"); }).substr(0, 17), "--set a.b=x: a.b:");
  root.Required("a").Required("b");
  EXPECT_EQ(ErrorOf([&] { root.CheckAllKeysUsed(); }), "--set c.d=2: c: unknown key");
}

TEST(YamlNodeTest, RelativePathsAreRelativeToWhoeverSaidThem) {
  namespace fs = std::filesystem;
  YamlNode root =
      YamlNode::LoadString("own: tex\ncam: {dir: a, sub: {dir: b}}\n", "/data/robots/r.yaml");
  root.Override("cam.dir", "from_cli", "--set cam.dir=from_cli");
  root.Override("cam.sub", "{dir: from_scenario}", "s.yaml:3:9: robot_overrides.cam.sub",
                "/data/scenarios");
  root.Override("plain", "p");  // no origin: the file's own
  EXPECT_EQ(root.Required("own").ResolvePath("tex"), "/data/robots/tex");
  EXPECT_EQ(root.Required("plain").ResolvePath("p"), "/data/robots/p");
  EXPECT_EQ(root.Required("cam").Required("dir").ResolvePath("from_cli"),
            (fs::current_path() / "from_cli").lexically_normal().string());
  // The innermost override decides; ".." and absolute paths are kept as written.
  const YamlNode sub = root.Required("cam").Required("sub").Required("dir");
  EXPECT_EQ(sub.ResolvePath("../textures"), "/data/textures");
  EXPECT_EQ(sub.ResolvePath("/abs/t"), "/abs/t");
  EXPECT_THAT(ErrorOf([&] { sub.Fail("no such folder"); }),
              HasSubstr("s.yaml:3:9: robot_overrides.cam.sub: cam.sub.dir: no such folder"));
}

}  // namespace
}  // namespace slamrig
