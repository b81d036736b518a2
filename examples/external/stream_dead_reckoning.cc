// Dead reckoning as a streaming slamrig estimator (`mode: stream`): a start to copy.
//
//   c++ -std=c++17 -O2 -ffp-contract=off stream_dead_reckoning.cc -o stream_dead_reckoning
//
// slamrig runs it as `command: [./stream_dead_reckoning]` and writes the run to its stdin as an
// MCAP stream of ROS 2 messages (CDR); after each /scan it waits for one
// geometry_msgs/PoseStamped on /estimate on stdout, stamped like the scan (docs/external.md).
// The pose is the wheel odometry between scans as slamrig's built-in dead reckoning computes
// it: encoder ticks (/joint_states) summed, gyro rates (/imu) averaged, one exact-arc step per
// scan (the geometry from the stream's `slamrig.robot` metadata). Same arithmetic, same bits
// (-ffp-contract=off, as slamrig is built). A log without encoders has its odometry poses on
// /odom: they are interpolated to each scan. C++17 standard library only; no slamrig code.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace {

const std::string kMagic("\x89MCAP0\r\n", 8);
const double kPi = 3.141592653589793238462643383279502884;

[[noreturn]] void Die(const char* what) {
  std::fprintf(stderr, "stream_dead_reckoning: %s\n", what);
  std::exit(1);
}

struct Bytes {  // bounds-checked little-endian reads; CDR aligns to the primitive's size
  std::string d;
  std::size_t p = 0, base = 0;  // base: where CDR alignment counts from
  template <typename T>
  T Get(bool align = false) {
    if (align) p += (sizeof(T) - (p - base) % sizeof(T)) % sizeof(T);
    if (p + sizeof(T) > d.size()) Die("a record or message shorter than its fields");
    T v;
    std::memcpy(&v, d.data() + p, sizeof(T));
    p += sizeof(T);
    return v;
  }
  std::string Str(bool cdr = false) {  // MCAP: uint32 length, bytes; CDR: the length counts a NUL
    const std::uint32_t n = Get<std::uint32_t>(cdr);
    if (p + n > d.size()) Die("a string longer than its record");
    p += n;
    return d.substr(p - n, cdr && n > 0 ? n - 1 : n);
  }
  std::int64_t StampNs() {  // std_msgs/Header: stamp, frame_id
    const std::int64_t sec = Get<std::int32_t>(true), nsec = Get<std::uint32_t>(true);
    Str(true);
    return sec * 1000000000 + nsec;
  }
};

template <typename T>
void Put(std::string* out, T v) {
  out->append(reinterpret_cast<const char*>(&v), sizeof(T));
}
void PutStr(std::string* out, const std::string& s) {
  Put(out, static_cast<std::uint32_t>(s.size()));
  *out += s;
}
void Record(std::uint8_t op, const std::string& content) {
  std::string head;
  Put(&head, op);
  Put(&head, static_cast<std::uint64_t>(content.size()));
  std::fwrite(head.data(), 1, head.size(), stdout);
  std::fwrite(content.data(), 1, content.size(), stdout);
}

void WritePose(std::uint32_t seq, std::int64_t t, double x, double y, double theta) {
  std::string cdr("\0\1\0\0", 4);  // PoseStamped: stamp, frame "odom", position, quaternion
  Put(&cdr, static_cast<std::int32_t>(t / 1000000000));
  Put(&cdr, static_cast<std::uint32_t>(t % 1000000000));
  Put(&cdr, std::uint32_t{5});
  cdr += std::string("odom\0\0\0\0\0\0\0\0", 12);  // the NUL, then padding to 8
  for (double v : {x, y, 0.0, 0.0, 0.0, std::sin(0.5 * theta), std::cos(0.5 * theta)}) Put(&cdr, v);
  std::string message;
  Put(&message, std::uint16_t{0});
  Put(&message, seq);
  Put(&message, static_cast<std::uint64_t>(t));
  Put(&message, static_cast<std::uint64_t>(t));
  Record(5, message + cdr);
  std::fflush(stdout);  // the bench waits for it
}

double Normalise(double a) {  // into (-pi, pi], as slamrig's Pose2
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

struct Pose {
  double x = 0, y = 0, th = 0;
};

Pose Compose(const Pose& a, const Pose& b) {
  const double c = std::cos(a.th), s = std::sin(a.th);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, Normalise(a.th + b.th)};
}

Pose Inverse(const Pose& a) {
  const double c = std::cos(a.th), s = std::sin(a.th);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, Normalise(-a.th)};
}

// Between two stamped odometry poses: linear, shortest yaw; held at the ends.
Pose Interpolate(std::int64_t t0, const Pose& p0, std::int64_t t1, const Pose& p1, std::int64_t t) {
  const double f = t1 > t0 ? std::clamp(double(t - t0) / double(t1 - t0), 0.0, 1.0) : 1.0;
  return {p0.x + f * (p1.x - p0.x), p0.y + f * (p1.y - p0.y),
          Normalise(p0.th + f * Normalise(p1.th - p0.th))};
}

double Sinc(double x) { return std::abs(x) < 1e-4 ? 1.0 - x * x / 6.0 : std::sin(x) / x; }

}  // namespace

int main() {
  std::string magic(8, '\0');
  if (std::fread(magic.data(), 1, 8, stdin) != 8 || magic != kMagic) Die("stdin is no MCAP stream");
  std::string out = kMagic, header, schema, channel;  // our stream: Header, Schema, Channel
  std::fwrite(out.data(), 1, out.size(), stdout);
  PutStr(&header, "ros2");
  PutStr(&header, "stream_dead_reckoning");
  Record(1, header);
  Put(&schema, std::uint16_t{1});
  PutStr(&schema, "geometry_msgs/msg/PoseStamped");
  PutStr(&schema, "ros2msg");
  PutStr(&schema, "std_msgs/Header header\ngeometry_msgs/Pose pose\n");
  Record(3, schema);
  Put(&channel, std::uint16_t{0});
  Put(&channel, std::uint16_t{1});
  PutStr(&channel, "/estimate");
  PutStr(&channel, "cdr");
  Put(&channel, std::uint32_t{0});
  Record(4, channel);

  std::map<std::string, std::string> robot;
  std::map<std::uint16_t, std::string> topics;
  std::vector<long long> total;
  double right = 0, left = 0, gyro = 0, tpr = 0, held = 0;
  int count = 0, odoms = 0;
  bool has_held = false, started = false;
  Pose pose, odom[2], last_odom;  // odom: the last two /odom poses, at odom_t
  std::int64_t odom_t[2] = {0, 0};
  std::int64_t last = 0;
  std::uint32_t seq = 0;
  while (true) {
    Bytes head{std::string(9, '\0')};
    if (std::fread(head.d.data(), 1, 9, stdin) != 9) Die("the stream ended without its Footer");
    const auto op = head.Get<std::uint8_t>();
    Bytes body{std::string(head.Get<std::uint64_t>(), '\0')};
    if (std::fread(body.d.data(), 1, body.d.size(), stdin) != body.d.size()) Die("cut record");
    if (op == 2) break;  // Footer: the end of the run
    if (op == 12) {      // Metadata: name, then a map (byte length, key, value, ...)
      const std::string name = body.Str();
      const std::size_t end = body.Get<std::uint32_t>() + body.p;
      while (body.p < end) {
        const std::string key = body.Str();
        robot[key] = body.Str();
      }
      if (name == "slamrig.robot") tpr = std::stod(robot.at("ticks_per_revolution"));
    } else if (op == 4) {  // Channel: id, schema id, topic
      const auto id = body.Get<std::uint16_t>();
      body.Get<std::uint16_t>();
      topics[id] = body.Str();
    } else if (op == 5) {  // Message: channel, sequence, log and publish time, CDR
      const std::string topic = topics[body.Get<std::uint16_t>()];
      Bytes cdr{body.d.substr(22), 4, 4};
      if (topic == "/joint_states") {  // wheel positions: accumulated ticks * 2 pi / tpr
        cdr.StampNs();
        std::vector<bool> is_right;
        for (std::uint32_t i = cdr.Get<std::uint32_t>(true); i > 0; --i) {
          const std::string n = cdr.Str(true);
          is_right.push_back(n.find("right") != std::string::npos || n == "wheel_fr" ||
                             n == "wheel_rr");
        }
        const std::uint32_t m = cdr.Get<std::uint32_t>(true);
        total.resize(m, 0);
        double r_sum = 0, l_sum = 0;
        int r_n = 0, l_n = 0;
        for (std::uint32_t i = 0; i < m && i < is_right.size(); ++i) {
          const long long ticks = std::llround(cdr.Get<double>(true) * tpr / (2.0 * kPi));
          const double delta = static_cast<double>(ticks - total[i]);
          total[i] = ticks;
          (is_right[i] ? r_sum : l_sum) += delta;
          ++(is_right[i] ? r_n : l_n);
        }
        right += r_sum / r_n;  // each side's mean, as slamrig's
        left += l_sum / l_n;
      } else if (topic == "/imu") {  // orientation, its covariance, then angular velocity
        cdr.StampNs();
        for (int i = 0; i < 15; ++i) cdr.Get<double>(true);
        gyro += cdr.Get<double>(true);
        ++count;
      } else if (topic == "/odom" && total.empty()) {  // a log's odometry poses, no encoders
        odom[0] = odom[1];
        odom_t[0] = odom_t[1];
        odom_t[1] = cdr.StampNs();
        cdr.Str(true);  // child_frame_id
        double v[7];
        for (double& d : v) d = cdr.Get<double>(true);
        odom[1] = {v[0], v[1], 2.0 * std::atan2(v[5], v[6])};
        if (odoms++ == 0) odom[0] = odom[1], odom_t[0] = odom_t[1];
      } else if (topic == "/scan") {
        const std::int64_t t = cdr.StampNs();
        if (total.empty() && odoms > 0) {  // the odometry poses interpolated to the scan
          const Pose o = Interpolate(odom_t[0], odom[0], odom_t[1], odom[1], t);
          if (started) pose = Compose(pose, Compose(Inverse(last_odom), o));
          last_odom = o;
        } else if (started) {
          const double dt = static_cast<double>(t - last) * 1e-9;
          const double mpt = 2.0 * kPi * std::stod(robot.at("wheel_radius_m")) / tpr;
          const double r_m = right * mpt, l_m = left * mpt;
          const double d = 0.5 * (r_m + l_m);
          double yaw = (r_m - l_m) / std::stod(robot.at("track_width_m"));
          if (robot.at("use_gyro") == "true") {
            if (count > 0) has_held = true, held = gyro / count;
            if (has_held) yaw = held * dt;
          }
          const double half = 0.5 * yaw, chord = d * Sinc(half);
          pose = Compose(pose, {chord * std::cos(half), chord * std::sin(half), Normalise(yaw)});
        }
        started = true;
        last = t;
        right = left = gyro = 0;
        count = 0;
        WritePose(seq++, t, pose.x, pose.y, pose.th);
      }
    }
  }
  std::string data_end, footer;
  Put(&data_end, std::uint32_t{0});
  Record(15, data_end);  // DataEnd, then a Footer without a summary, then the magic
  Put(&footer, std::uint64_t{0});
  Put(&footer, std::uint64_t{0});
  Put(&footer, std::uint32_t{0});
  Record(2, footer);
  std::fwrite(kMagic.data(), 1, kMagic.size(), stdout);
  return std::fflush(stdout) == 0 ? 0 : 1;
}
