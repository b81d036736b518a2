#include "scenarios/live_server.h"

#include <unistd.h>

// clang-format off
// First: Boost.Asio 1.74 uses std::exchange without including <utility>.
#include <utility>
// clang-format on

#include <algorithm>
#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <unordered_map>
#include <vector>

#include "slam/types/error.h"
#include "slam/types/interrupt.h"

namespace slamrig::scenario {
namespace {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = net::ip::tcp;
using Json = nlohmann::json;
using SteadyClock = std::chrono::steady_clock;

constexpr const char* kSubprotocol = "foxglove.websocket.v1";
constexpr const char* kPaceParameter = "slamrig.pace";
// Binary opcodes of the protocol (server to client).
constexpr unsigned char kMessageData = 0x01;
constexpr unsigned char kTimeData = 0x02;
// A client's own messages are small JSON objects: anything longer is refused.
constexpr std::size_t kMaxClientMessage = 1u << 20;
// Time frames at most this often in run time (a scan's messages share one).
constexpr std::int64_t kTimePeriodNs = 10'000'000;
// The pacing starts afresh (instead of sleeping through it) after a jump in the run's clock
// longer than this, or when it has fallen behind the wall clock by more than this.
constexpr double kPaceSlackS = 1.0;

void PutLe(std::string* out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xff));
}

std::string Dump(const Json& j) { return j.dump(-1, ' ', false, Json::error_handler_t::replace); }

// Whether the comma-separated Sec-WebSocket-Protocol list offers `protocol`.
bool Offers(std::string_view list, std::string_view protocol) {
  while (!list.empty()) {
    const std::size_t comma = list.find(',');
    std::string_view item = list.substr(0, comma);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item == protocol) return true;
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
  }
  return false;
}

struct Frame {
  std::shared_ptr<const std::string> data;
  bool binary = true;
  bool message = false;            // a message frame (counted as sent)
  std::uint32_t subscription = 0;  // a message frame's
  bool essential = false;          // serverInfo and advertisements: never dropped
};

struct Channel {
  std::uint32_t id = 0;
  std::string topic;
  slam::RosType type{};
  bool latched = false;
  std::shared_ptr<const std::string> last;  // a latched topic's last message
  Time last_time;
};

}  // namespace

struct LiveServer::Impl {
  struct Session;

  LiveOptions options;
  net::io_context ioc{1};
  net::executor_work_guard<net::io_context::executor_type> work{ioc.get_executor()};
  tcp::acceptor acceptor{ioc};
  std::uint16_t port = 0;
  std::thread thread;
  bool closed = false;

  // Shared by the run's thread and the server's thread.
  std::mutex mu;
  std::vector<std::shared_ptr<Session>> sessions;  // open ones
  std::vector<Channel> channels;                   // id - 1 is the index
  std::unordered_map<std::string, std::size_t> channel_index;
  std::int64_t last_time_ns = -1;  // of the last time frame
  std::atomic<double> pace{1.0};
  std::atomic<int> watchers{0};  // sessions with at least one subscription
  std::atomic<std::uint64_t> sent{0}, dropped{0}, clients{0};

  // The run's thread only: the pacing's anchor, and whether the run still waits for a watcher.
  bool holding = false;
  bool anchored = false;
  SteadyClock::time_point anchor_wall;
  std::int64_t anchor_ns = 0, last_pace_ns = 0;
  double anchor_factor = 0.0;

  void Accept();
  // With `mu` held: the channel of `topic`, made and advertised to every client if new.
  Channel& Declare(const std::string& topic, slam::RosType type, bool latched);
  void Open(const std::shared_ptr<Session>& s);
  void Drop(const std::shared_ptr<Session>& s);
  // With `mu` held: queues `frame` for `s`; a message frame that does not fit is dropped.
  void Enqueue(Session& s, Frame frame);
  void Handle(const std::shared_ptr<Session>& s, const std::string& text);
  void Subscribe(Session& s, const Json& request);
  void Unsubscribe(Session& s, const Json& request);
  void Parameters(Session& s, const Json& request, bool set);
  void Status(Session& s, int level, const std::string& message);
  void CountWatchers();
  // With `mu` held: a time frame to every client when the run's clock has advanced enough.
  void Clock(Time time);
  static std::string Advertise(const std::vector<const Channel*>& channels);
  static std::shared_ptr<const std::string> DataFrame(std::uint32_t subscription, Time time,
                                                      std::string_view payload);
};

struct LiveServer::Impl::Session : std::enable_shared_from_this<Session> {
  Session(tcp::socket socket, Impl* owner) : ws(std::move(socket)), server(owner) {}

  websocket::stream<beast::tcp_stream> ws;
  Impl* server;
  beast::flat_buffer buffer;
  http::request<http::string_body> request;
  Frame current;  // the frame being written (the server's thread only)
  // Guarded by server->mu.
  std::map<std::uint32_t, std::uint32_t> subscription_of;  // channel id -> subscription id
  std::map<std::uint32_t, std::uint32_t> channel_of;       // subscription id -> channel id
  std::deque<Frame> queue;
  std::size_t queued_bytes = 0;
  bool writing = false;
  bool open = false;

  void Start();
  void Read();
  void WriteNext();
};

void LiveServer::Impl::Session::Start() {
  beast::get_lowest_layer(ws).expires_after(std::chrono::seconds(10));
  http::async_read(
      ws.next_layer(), buffer, request,
      [self = shared_from_this()](beast::error_code ec, std::size_t) {
        if (ec) return;
        const auto offered = self->request[http::field::sec_websocket_protocol];
        if (!websocket::is_upgrade(self->request) ||
            !Offers(std::string_view(offered.data(), offered.size()), kSubprotocol)) {
          // Not a Foxglove client: the connection ends here.
          beast::error_code ignored;
          beast::get_lowest_layer(self->ws).socket().close(ignored);
          return;
        }
        beast::get_lowest_layer(self->ws).expires_never();
        // A client that answers no ping for a minute is gone; one that only listens (Foxglove
        // sends nothing while it watches) answers the pings and stays.
        websocket::stream_base::timeout timeout{};
        timeout.handshake_timeout = std::chrono::seconds(30);
        timeout.idle_timeout = std::chrono::seconds(60);
        timeout.keep_alive_pings = true;
        self->ws.set_option(timeout);
        self->ws.set_option(websocket::stream_base::decorator([](websocket::response_type& r) {
          r.set(http::field::sec_websocket_protocol, kSubprotocol);
          r.set(http::field::server, "slamrig");
        }));
        self->ws.read_message_max(kMaxClientMessage);
        self->ws.async_accept(self->request, [self](beast::error_code accept_ec) {
          if (accept_ec) return;
          self->buffer.clear();
          self->server->Open(self);
          self->Read();
        });
      });
}

void LiveServer::Impl::Session::Read() {
  ws.async_read(buffer, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) {
      self->server->Drop(self);
      return;
    }
    if (self->ws.got_text()) {
      const std::string text = beast::buffers_to_string(self->buffer.data());
      self->server->Handle(self, text);
    } else {
      std::lock_guard lock(self->server->mu);
      self->server->Status(*self, 1, "binary client messages are not supported");
    }
    self->buffer.consume(self->buffer.size());
    self->Read();
  });
}

void LiveServer::Impl::Session::WriteNext() {
  {
    std::lock_guard lock(server->mu);
    if (!open || queue.empty()) {
      writing = false;
      return;
    }
    current = std::move(queue.front());
    queue.pop_front();
    queued_bytes -= current.data->size();
  }
  ws.binary(current.binary);
  ws.async_write(net::buffer(*current.data),
                 [self = shared_from_this()](beast::error_code ec, std::size_t) {
                   if (ec) {
                     self->server->Drop(self);
                     return;
                   }
                   if (self->current.message) ++self->server->sent;
                   self->current = Frame();
                   self->WriteNext();
                 });
}

void LiveServer::Impl::Accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket socket) {
    if (ec == net::error::operation_aborted || !acceptor.is_open()) return;
    if (!ec) std::make_shared<Session>(std::move(socket), this)->Start();
    Accept();
  });
}

Channel& LiveServer::Impl::Declare(const std::string& topic, slam::RosType type, bool latched) {
  const auto [it, added] = channel_index.try_emplace(topic, channels.size());
  if (added) {
    Channel c;
    c.id = static_cast<std::uint32_t>(channels.size() + 1);
    c.topic = topic;
    c.type = type;
    c.latched = latched;
    channels.push_back(std::move(c));
    if (!sessions.empty()) {
      auto advertise = std::make_shared<const std::string>(Advertise({&channels.back()}));
      for (const auto& s : sessions) Enqueue(*s, {advertise, false, false, 0, true});
    }
  }
  return channels[it->second];
}

void LiveServer::Impl::Open(const std::shared_ptr<Session>& s) {
  ++clients;
  std::lock_guard lock(mu);
  s->open = true;
  sessions.push_back(s);
  Json info = {{"op", "serverInfo"},
               {"name", "slamrig"},
               {"capabilities", Json::array({"parameters", "time"})},
               {"metadata", Json::object()},
               {"sessionId", std::to_string(::getpid())}};
  Enqueue(*s, {std::make_shared<const std::string>(Dump(info)), false, false, 0, true});
  std::vector<const Channel*> all;
  for (const Channel& c : channels) all.push_back(&c);
  Enqueue(*s, {std::make_shared<const std::string>(Advertise(all)), false, false, 0, true});
}

void LiveServer::Impl::Drop(const std::shared_ptr<Session>& s) {
  std::lock_guard lock(mu);
  if (!s->open) return;
  s->open = false;
  s->queue.clear();
  s->queued_bytes = 0;
  s->subscription_of.clear();
  s->channel_of.clear();
  std::erase(sessions, s);
  CountWatchers();
  beast::error_code ignored;
  beast::get_lowest_layer(s->ws).socket().close(ignored);
}

void LiveServer::Impl::Enqueue(Session& s, Frame frame) {
  if (!s.open) return;
  // Only the frames that tell a client what exists bypass the bound: whatever else a client
  // causes (messages, time, status and parameter replies to its requests) waits in it.
  if (!frame.essential && s.queued_bytes + frame.data->size() > options.queue_bytes) {
    if (frame.message) ++dropped;
    return;
  }
  s.queued_bytes += frame.data->size();
  s.queue.push_back(std::move(frame));
  if (!s.writing) {
    s.writing = true;
    net::post(ioc, [self = s.shared_from_this()] { self->WriteNext(); });
  }
}

void LiveServer::Impl::Clock(Time time) {
  if (sessions.empty() || time.ns < last_time_ns + kTimePeriodNs) return;
  last_time_ns = time.ns;
  auto frame = std::make_shared<std::string>(1, static_cast<char>(kTimeData));
  PutLe(frame.get(), static_cast<std::uint64_t>(std::max<std::int64_t>(time.ns, 0)), 8);
  // A time frame is small and may be dropped like a message (it is not counted as one).
  for (const auto& s : sessions) Enqueue(*s, {frame, true});
}

void LiveServer::Impl::CountWatchers() {
  int n = 0;
  for (const auto& s : sessions) n += s->subscription_of.empty() ? 0 : 1;
  watchers = n;
}

std::string LiveServer::Impl::Advertise(const std::vector<const Channel*>& channels) {
  Json list = Json::array();
  for (const Channel* c : channels) {
    list.push_back({{"id", c->id},
                    {"topic", c->topic},
                    {"encoding", "cdr"},
                    {"schemaName", std::string(slam::RosTypeName(c->type))},
                    {"schema", slam::RosMessageDefinition(c->type)},
                    {"schemaEncoding", "ros2msg"}});
  }
  return Dump(Json{{"op", "advertise"}, {"channels", list}});
}

std::shared_ptr<const std::string> LiveServer::Impl::DataFrame(std::uint32_t subscription,
                                                               Time time,
                                                               std::string_view payload) {
  auto frame = std::make_shared<std::string>();
  frame->reserve(13 + payload.size());
  frame->push_back(static_cast<char>(kMessageData));
  PutLe(frame.get(), subscription, 4);
  PutLe(frame.get(), static_cast<std::uint64_t>(std::max<std::int64_t>(time.ns, 0)), 8);
  frame->append(payload);
  return frame;
}

void LiveServer::Impl::Status(Session& s, int level, const std::string& message) {
  Json status = {{"op", "status"}, {"level", level}, {"message", message}};
  Enqueue(s, {std::make_shared<const std::string>(Dump(status)), false, false});
}

void LiveServer::Impl::Handle(const std::shared_ptr<Session>& s, const std::string& text) {
  std::lock_guard lock(mu);
  if (!s->open) return;
  const Json request = Json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (request.is_discarded() || !request.is_object()) {
    Status(*s, 2, "not a JSON object");
    return;
  }
  try {
    const std::string op = request.value("op", "");
    if (op == "subscribe") {
      Subscribe(*s, request);
    } else if (op == "unsubscribe") {
      Unsubscribe(*s, request);
    } else if (op == "getParameters" || op == "setParameters") {
      Parameters(*s, request, op == "setParameters");
    } else {
      Status(*s, 1, "unsupported op '" + op + "'");
    }
  } catch (const Json::exception& e) {
    Status(*s, 2, std::string("malformed request: ") + e.what());
  }
}

void LiveServer::Impl::Subscribe(Session& s, const Json& request) {
  for (const Json& sub : request.at("subscriptions")) {
    const auto id = sub.at("id").get<std::uint32_t>();
    const auto channel = sub.at("channelId").get<std::uint32_t>();
    if (channel == 0 || channel > channels.size()) {
      Status(s, 1, "subscribe: no channel " + std::to_string(channel));
      continue;
    }
    if (s.channel_of.contains(id) || s.subscription_of.contains(channel)) {
      Status(s, 1,
             "subscribe: subscription " + std::to_string(id) + " or channel " +
                 std::to_string(channel) + " is already in use");
      continue;
    }
    s.channel_of[id] = channel;
    s.subscription_of[channel] = id;
    // A latched topic's last message, as a late subscriber of a transient-local topic gets it.
    const Channel& c = channels[channel - 1];
    if (c.last) Enqueue(s, {DataFrame(id, c.last_time, *c.last), true, true, id});
  }
  CountWatchers();
}

void LiveServer::Impl::Unsubscribe(Session& s, const Json& request) {
  for (const Json& id_json : request.at("subscriptionIds")) {
    const auto id = id_json.get<std::uint32_t>();
    const auto it = s.channel_of.find(id);
    if (it == s.channel_of.end()) {
      Status(s, 1, "unsubscribe: no subscription " + std::to_string(id));
      continue;
    }
    s.subscription_of.erase(it->second);
    s.channel_of.erase(it);
    // What is queued for it is not sent any more.
    std::erase_if(s.queue, [&](const Frame& f) {
      const bool gone = f.message && f.subscription == id;
      if (gone) s.queued_bytes -= f.data->size();
      return gone;
    });
  }
  CountWatchers();
}

void LiveServer::Impl::Parameters(Session& s, const Json& request, bool set) {
  bool asked = !set;
  if (set) {
    for (const Json& p : request.at("parameters")) {
      const std::string name = p.at("name").get<std::string>();
      if (name != kPaceParameter) {
        Status(s, 1, "setParameters: unknown parameter '" + name + "'; only " + kPaceParameter);
        continue;
      }
      const Json& value = p.contains("value") ? p.at("value") : Json();
      if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0) {
        Status(s, 2,
               std::string("setParameters: ") + kPaceParameter +
                   " must be a number >= 0 (0 as fast as possible, 1 real time, 2 twice as fast)");
        continue;
      }
      pace = value.get<double>();
      asked = true;
    }
  } else if (request.contains("parameterNames") && !request.at("parameterNames").empty()) {
    asked = false;
    for (const Json& n : request.at("parameterNames"))
      asked |= n.get<std::string>() == kPaceParameter;
  }
  Json values = Json::array();
  if (asked)
    values.push_back({{"name", kPaceParameter}, {"value", pace.load()}, {"type", "float64"}});
  Json reply = {{"op", "parameterValues"}, {"parameters", values}};
  if (request.contains("id")) reply["id"] = request.at("id");
  Enqueue(s, {std::make_shared<const std::string>(Dump(reply)), false, false});
}

LiveServer::LiveServer(LiveOptions options) : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = std::move(options);
  m.pace = m.options.pace;
  m.holding = m.options.wait_for_watcher;
  const std::string where = m.options.address + ":" + std::to_string(m.options.port);
  beast::error_code ec;
  const net::ip::address address = net::ip::make_address(m.options.address, ec);
  if (ec) throw OutputError("live view: '" + m.options.address + "' is not an IP address");
  const tcp::endpoint endpoint(address, m.options.port);
  m.acceptor.open(endpoint.protocol(), ec);
  if (!ec) m.acceptor.set_option(net::socket_base::reuse_address(true), ec);
  if (!ec) m.acceptor.bind(endpoint, ec);
  if (!ec) m.acceptor.listen(net::socket_base::max_listen_connections, ec);
  if (ec) throw OutputError("live view: cannot listen on " + where + ": " + ec.message());
  m.port = m.acceptor.local_endpoint().port();
  m.Accept();
  m.thread = std::thread([&m] {
    for (;;) {
      try {
        m.ioc.run();
        return;
      } catch (const std::exception& e) {  // a handler failed: that connection is lost, not the run
        std::fprintf(stderr, "live view: %s\n", e.what());
      }
    }
  });
}

LiveServer::~LiveServer() { Close(0.0); }

std::uint16_t LiveServer::port() const { return impl_->port; }

std::string LiveServer::url() const {
  return "ws://" + impl_->options.address + ":" + std::to_string(impl_->port);
}

LiveStats LiveServer::stats() const {
  return {impl_->sent.load(), impl_->dropped.load(), impl_->clients.load()};
}

void LiveServer::Message(const std::string& topic, slam::RosType type, bool latched, Time time,
                         std::string_view cdr) {
  Impl& m = *impl_;
  std::lock_guard lock(m.mu);
  if (m.closed) return;
  Channel& channel = m.Declare(topic, type, latched);
  if (channel.latched) {
    channel.last = std::make_shared<const std::string>(cdr);
    channel.last_time = time;
  }
  if (m.sessions.empty()) return;
  m.Clock(time);
  for (const auto& s : m.sessions) {
    const auto sub = s->subscription_of.find(channel.id);
    if (sub != s->subscription_of.end()) {
      m.Enqueue(*s, {Impl::DataFrame(sub->second, time, cdr), true, true, sub->second});
    }
  }
}

bool LiveServer::Wants(const std::string& topic, slam::RosType type, bool latched) {
  Impl& m = *impl_;
  std::lock_guard lock(m.mu);
  if (m.closed) return false;
  const Channel& channel = m.Declare(topic, type, latched);
  if (channel.latched) return true;
  for (const auto& s : m.sessions) {
    if (s->subscription_of.contains(channel.id)) return true;
  }
  return false;
}

void LiveServer::Pace(Time time) {
  Impl& m = *impl_;
  if (m.holding) {
    // Held from the first step that advertised a topic, which a client can subscribe to.
    {
      std::lock_guard lock(m.mu);
      if (m.channels.empty()) return;
    }
    while (m.watchers.load() == 0 && InterruptSignal() == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    m.holding = false;
  }
  // The clients' clock follows the run's even when no message they take is made.
  if (m.watchers.load() > 0) {
    std::lock_guard lock(m.mu);
    if (!m.closed) m.Clock(time);
  }
  for (;;) {
    const double factor = m.pace.load();
    if (m.watchers.load() == 0 || !(factor > 0.0) || InterruptSignal() != 0) {
      m.anchored = false;
      return;
    }
    const auto now = SteadyClock::now();
    const bool jumped =
        std::abs(static_cast<double>(time.ns - m.last_pace_ns)) * 1e-9 > kPaceSlackS;
    m.last_pace_ns = time.ns;
    if (!m.anchored || factor != m.anchor_factor || jumped) {
      m.anchored = true;
      m.anchor_wall = now;
      m.anchor_ns = time.ns;
      m.anchor_factor = factor;
      return;
    }
    const auto target =
        m.anchor_wall +
        std::chrono::duration_cast<SteadyClock::duration>(std::chrono::duration<double>(
            static_cast<double>(time.ns - m.anchor_ns) * 1e-9 / factor));
    if (target <= now) {
      // Behind the wall clock (the run is slower than the pace): start afresh rather than rush.
      if (std::chrono::duration<double>(now - target).count() > kPaceSlackS) m.anchored = false;
      return;
    }
    std::this_thread::sleep_for(
        std::min<SteadyClock::duration>(target - now, std::chrono::milliseconds(50)));
  }
}

void LiveServer::Close(double drain_s) {
  Impl& m = *impl_;
  {
    std::lock_guard lock(m.mu);
    if (m.closed) return;
    m.closed = true;
  }
  // What is queued goes out, for at most drain_s.
  const auto deadline = SteadyClock::now() + std::chrono::duration_cast<SteadyClock::duration>(
                                                 std::chrono::duration<double>(drain_s));
  // Nor longer than while a frame was written to some client in the last kStuck.
  constexpr auto kStuck = std::chrono::milliseconds(500);
  std::uint64_t last_sent = m.sent.load();
  auto last_progress = SteadyClock::now();
  for (;;) {
    bool idle = true;
    {
      std::lock_guard lock(m.mu);
      for (const auto& s : m.sessions) idle &= !s->writing && s->queue.empty();
    }
    const auto now = SteadyClock::now();
    if (m.sent.load() != last_sent) {
      last_sent = m.sent.load();
      last_progress = now;
    }
    if (idle || now >= deadline || now - last_progress > kStuck || InterruptSignal() != 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Every connection ends with a close frame (one still writing is cut), then the thread ends.
  std::atomic<int> pending{1};
  net::post(m.ioc, [&m, &pending] {
    beast::error_code ignored;
    m.acceptor.close(ignored);
    std::vector<std::shared_ptr<Impl::Session>> open;
    {
      std::lock_guard lock(m.mu);
      open = m.sessions;
      m.sessions.clear();
      m.watchers = 0;
      for (const auto& s : open) {
        s->open = false;
        s->queue.clear();
      }
    }
    for (const auto& s : open) {
      if (s->writing) {
        beast::get_lowest_layer(s->ws).socket().close(ignored);
        continue;
      }
      ++pending;
      s->ws.async_close(websocket::close_code::going_away,
                        [s, &pending](beast::error_code) { --pending; });
    }
    --pending;
  });
  const auto give_up = SteadyClock::now() + std::chrono::milliseconds(500);
  while (pending.load() > 0 && SteadyClock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  m.work.reset();
  m.ioc.stop();
  if (m.thread.joinable()) m.thread.join();
}

}  // namespace slamrig::scenario
