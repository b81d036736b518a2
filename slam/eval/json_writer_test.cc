#include "slam/eval/json_writer.h"

#include <gtest/gtest.h>

#include <limits>

namespace slamrig::slam {
namespace {

TEST(JsonWriterTest, WritesNestedObjectsInOrder) {
  JsonWriter json;
  json.String("name", "a \"b\"\n").Integer("n", 3);
  json.BeginObject("ate")
      .Number("rmse", 0.125)
      .Number("bad", std::numeric_limits<double>::quiet_NaN())
      .EndObject();
  json.Bool("ok", true).StringArray("notes", {"x", "y"});
  EXPECT_EQ(json.Finish(),
            "{\n  \"name\": \"a \\\"b\\\"\\n\",\n  \"n\": 3,\n  \"ate\": {\n    \"rmse\": 0.125,\n"
            "    \"bad\": null\n  },\n  \"ok\": true,\n  \"notes\": [\"x\", \"y\"]\n}\n");
}

TEST(JsonWriterTest, WritesNumberArrays) {
  JsonWriter json;
  json.NumberArray("from_s", {1.5, std::numeric_limits<double>::infinity(), 1e-10})
      .NumberArray("none", {});
  EXPECT_EQ(json.Finish(), "{\n  \"from_s\": [1.5, null, 1e-10],\n  \"none\": []\n}\n");
}

}  // namespace
}  // namespace slamrig::slam
