#include "scenarios/live_server.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "slam/io/bag/bag_writer.h"
#include "slam/types/error.h"

namespace slamrig::scenario {
namespace {

LiveOptions AnyPort() {
  LiveOptions options;
  options.port = 0;
  return options;
}

// A second server on a port in use fails at once with one message naming the address and port.
TEST(LiveServerTest, PortInUseIsAnErrorNamingIt) {
  LiveServer first(AnyPort());
  ASSERT_NE(first.port(), 0);
  EXPECT_EQ(first.url(), "ws://127.0.0.1:" + std::to_string(first.port()));
  LiveOptions same;
  same.port = first.port();
  try {
    LiveServer second(same);
    FAIL() << "a second server listened on port " << first.port();
  } catch (const OutputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("127.0.0.1:" + std::to_string(first.port())), std::string::npos) << what;
    EXPECT_NE(what.find("in use"), std::string::npos) << what;
  }
  LiveOptions bad = AnyPort();
  bad.address = "not an address";
  EXPECT_THROW(LiveServer{bad}, OutputError);
}

// Without a client the run never waits: pacing returns at once however far the clock jumps, and
// messages cost only their bookkeeping (nothing is queued, sent or dropped).
TEST(LiveServerTest, WithoutAClientNothingWaits) {
  LiveOptions options = AnyPort();
  options.pace = 1.0;
  LiveServer server(options);
  const std::string payload(100000, 'x');
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 2000; ++i) {
    const Time t = Time::FromSeconds(0.5 * i);
    server.Message("/topic" + std::to_string(i % 7), slam::RosType::kString, i % 7 == 0, t,
                   payload);
    server.Pace(t);
  }
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(wall_s, 0.5);  // 1000 s of run time at real time would take 1000 s
  // No one wants a message of a topic that is not latched; a latched one is kept for later.
  EXPECT_FALSE(server.Wants("/topic1", slam::RosType::kString, false));
  EXPECT_TRUE(server.Wants("/topic0", slam::RosType::kString, true));
  const LiveStats stats = server.stats();
  EXPECT_EQ(stats.clients, 0u);
  EXPECT_EQ(stats.sent, 0u);
  EXPECT_EQ(stats.dropped, 0u);
  server.Close(1.0);
  server.Close(1.0);  // twice is fine
}

// Records every message a BagWriter gives its sinks.
struct Capture : slam::MessageSink {
  struct Entry {
    std::string topic;
    slam::RosType type;
    bool latched;
    std::int64_t ns;
    std::string cdr;
    bool operator==(const Entry&) const = default;
  };
  std::vector<Entry> entries;
  bool wants = true;
  bool Wants(const std::string&, slam::RosType, bool latched) override { return wants || latched; }
  void Message(const std::string& topic, slam::RosType type, bool latched, Time time,
               std::string_view cdr) override {
    entries.push_back({topic, type, latched, time.ns, std::string(cdr)});
  }
};

// The live view and the recording share one source: a writer without storage gives its sinks
// exactly the messages a file writer gives them (and writes), the latched /tf_static marked so.
TEST(MessageSinkTest, AWriterWithoutStorageFeedsTheSameMessagesAsAFileWriter) {
  const std::string path = testing::TempDir() + "/sink_test.mcap";
  std::filesystem::remove(path);
  slam::BagWriterOptions options;
  options.single_file = true;
  Capture to_file, to_sink;
  slam::BagWriter file(path, options);
  slam::BagWriter bare(options);
  file.AddSink(&to_file);
  bare.AddSink(&to_sink);
  for (slam::BagWriter* w : {&file, &bare}) {
    for (int i = 0; i < 30; ++i) {
      LaserScan scan;
      scan.time = Time::FromSeconds(0.025 * i);
      scan.angle_increment_rad = 0.01;
      scan.range_max_m = 10.0;
      scan.ranges_m = {1.0f + 0.01f * static_cast<float>(i), 2.0f, 3.0f};
      w->Write(Record{scan});
      w->Write(Record{OdometryPose{scan.time, Pose2(0.1 * i, 0.0, 0.01 * i)}});
      w->Write(GroundTruthPose{scan.time, Pose2(0.1 * i, 0.0, 0.0)});
    }
    w->WriteMessage("/truth/map", slam::RosType::kString, true, Time::FromSeconds(0.0), "map");
    w->Commit();
  }
  EXPECT_EQ(to_file.entries, to_sink.entries);
  EXPECT_EQ(to_sink.entries.size(), bare.message_count());
  EXPECT_EQ(file.message_count(), bare.message_count());
  EXPECT_GT(std::filesystem::file_size(path), 0u);
  int scans = 0, statics = 0;
  for (const Capture::Entry& e : to_sink.entries) {
    scans += e.topic == "/scan";
    if (e.topic == "/tf_static") {
      ++statics;
      EXPECT_TRUE(e.latched);
    }
    if (e.topic == "/scan") {
      EXPECT_FALSE(e.latched);
    }
  }
  EXPECT_EQ(scans, 30);
  EXPECT_EQ(statics, 1);
  std::filesystem::remove(path);
}

// Messages no sink wants are not made when there is no file; latched ones always are; with a
// file every message is made and given to the sinks whatever they want.
TEST(MessageSinkTest, OnlyWantedMessagesAreMadeWithoutAFile) {
  slam::BagWriterOptions options;
  options.single_file = true;
  const std::string path = testing::TempDir() + "/sink_want_test.mcap";
  std::filesystem::remove(path);
  Capture bare_sink, file_sink;
  bare_sink.wants = file_sink.wants = false;
  slam::BagWriter bare(options);
  slam::BagWriter file(path, options);
  bare.AddSink(&bare_sink);
  file.AddSink(&file_sink);
  for (slam::BagWriter* w : {&bare, &file}) {
    for (int i = 0; i < 10; ++i) {
      LaserScan scan;
      scan.time = Time::FromSeconds(0.1 * i);
      scan.ranges_m = {1.0f, 2.0f};
      w->Write(Record{scan});
    }
    w->Commit();
  }
  ASSERT_EQ(bare_sink.entries.size(), 1u);
  EXPECT_EQ(bare_sink.entries[0].topic, "/tf_static");
  EXPECT_EQ(file_sink.entries.size(), file.message_count());
  EXPECT_GT(file.message_count(), 10u);  // the scans, /clock and /tf_static
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace slamrig::scenario
