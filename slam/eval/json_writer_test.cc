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

}  // namespace
}  // namespace slamrig::slam
