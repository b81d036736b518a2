// Independent check of `slamrig run --live` with Foxglove's own WebSocket client
// (@foxglove/ws-protocol over the `ws` package) and its ROS 2 decoder
// (@foxglove/rosmsg, @foxglove/rosmsg2-serialization).
//
// Usage: node live_check.mjs NODE_MODULES_PARENT watch URL [from-start]
//        node live_check.mjs NODE_MODULES_PARENT stall URL
// watch: connects while the run goes, checks serverInfo (capabilities parameters and time),
//   subscribes to /scan, /tf, /pf/pose, /dead_reckoning/pose, /pf/particles, /pf/map and /clock
//   as they are advertised and, a second later, to /tf_static and /live/alignments (sent once
//   at the start: they arrive only as the latched topics' last messages); decodes every message with the schema of
//   its advertisement and checks types and fields (stamps equal to the frame's log time,
//   increasing on each topic; finite poses; the laser and the base's static transforms); asks
//   for `slamrig.pace` 2 and checks that the run's clock then advances at most ~2x the wall
//   clock; unsubscribes /scan and checks that no /scan arrives after; then disconnects
//   mid-run (the run goes on: the test checks that it ends with the same results).
//   With from-start (a run held by --live-wait until this client subscribes), the first /clock
//   message must be of the run's first second.
// stall: connects, subscribes to every channel, then never reads again (its socket paused),
//   until it is killed: the run must not wait for it.
// Exit 0 when everything holds; otherwise one line per failure and exit 1.
import path from "node:path";
import { createRequire } from "node:module";

const [, , modulesParent, mode, url, option] = process.argv;
const require = createRequire(path.join(path.resolve(modulesParent), "package.json"));
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const WebSocket = require("ws");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");

const errors = [];
const fail = (msg) => errors.push(msg);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));
const giveUp = setTimeout(() => {
  console.error(`live_check: ${mode}: timed out; ${errors.join("; ")}`);
  process.exit(1);
}, 45000);

function stall() {
  // A client that asks for everything and then stops reading: the server's queue for it fills.
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  let next = 1;
  ws.on("message", (data, isBinary) => {
    if (isBinary) return;
    const msg = JSON.parse(data.toString());
    if (msg.op !== "advertise") return;
    const subscriptions = msg.channels.map((c) => ({ id: next++, channelId: c.id }));
    ws.send(JSON.stringify({ op: "subscribe", subscriptions }));
    // Once the maps come (the largest messages), it reads nothing more.
    if (msg.channels.some((c) => c.topic === "/pf/map")) {
      ws._socket.pause();
      console.log(`live_check: stall: subscribed to ${next - 1} channels, not reading any more`);
    }
  });
  ws.on("error", () => {});
  ws.on("close", () => process.exit(0));  // the server ended the connection at its end
}

const expectedTypes = {
  "/scan": ["sensor_msgs/msg/LaserScan"],
  "/tf": ["tf2_msgs/msg/TFMessage"],
  "/tf_static": ["tf2_msgs/msg/TFMessage"],
  "/live/alignments": ["tf2_msgs/msg/TFMessage"],
  "/pf/pose": ["geometry_msgs/msg/PoseWithCovarianceStamped", "geometry_msgs/msg/PoseStamped"],
  "/dead_reckoning/pose": ["geometry_msgs/msg/PoseWithCovarianceStamped", "geometry_msgs/msg/PoseStamped"],
  "/pf/particles": ["geometry_msgs/msg/PoseArray"],
  "/pf/map": ["nav_msgs/msg/OccupancyGrid"],
  "/clock": ["rosgraph_msgs/msg/Clock"],
};

// Sent once early in the run: a subscriber a second later gets them only as the latched copy.
const latched = ["/tf_static", "/live/alignments"];

const stampNs = (s) => BigInt(s.sec) * 1000000000n + BigInt(s.nanosec ?? s.nsec);
const finite = (...v) => v.every((x) => Number.isFinite(x));

// Checks one decoded message of `topic` sent at log time `t` (ns, BigInt).
function checkMessage(topic, m, t, state) {
  const header = m.header ?? (m.transforms?.[0]?.header);
  if (topic === "/clock") {
    if (stampNs(m.clock) !== t) fail(`/clock ${stampNs(m.clock)} sent at ${t}`);
  } else if (header && stampNs(header.stamp) !== t) {
    fail(`${topic}: header stamp ${stampNs(header.stamp)} ns, sent at log time ${t} ns`);
  }
  const last = state.lastTime.get(topic);
  if (last !== undefined && topic !== "/tf" && t <= last) {
    fail(`${topic}: log time ${t} ns not after the previous ${last} ns`);
  }
  state.lastTime.set(topic, t);
  if (topic === "/scan") {
    if (m.ranges.length < 10 || m.angle_increment <= 0) fail(`/scan: ${m.ranges.length} ranges`);
    if (m.header.frame_id !== "laser") fail(`/scan: frame ${m.header.frame_id}`);
  } else if (topic.endsWith("/pose")) {
    const p = (m.pose.pose ?? m.pose).position;
    if (!finite(p.x, p.y, p.z)) fail(`${topic}: position not finite`);
    if (m.header.frame_id !== `${topic.split("/")[1]}/map`) fail(`${topic}: frame ${m.header.frame_id}`);
    if (m.pose.covariance && m.pose.covariance.length !== 36) fail(`${topic}: covariance length`);
  } else if (topic === "/pf/particles") {
    if (m.poses.length === 0) fail("/pf/particles: no particles");
    if (!m.poses.every((q) => finite(q.position.x, q.position.y))) fail("/pf/particles: not finite");
  } else if (topic === "/pf/map") {
    if (m.data.length !== m.info.width * m.info.height) fail("/pf/map: data size");
    if (!(m.info.resolution > 0)) fail("/pf/map: resolution");
  } else if (topic === "/tf_static") {
    const pairs = m.transforms.map((x) => `${x.header.frame_id}->${x.child_frame_id}`);
    for (const want of ["truth/base_link->base_link", "base_link->laser"]) {
      if (!pairs.includes(want)) fail(`/tf_static: no ${want} in ${pairs.join(", ")}`);
    }
  } else if (topic === "/live/alignments") {
    const pairs = m.transforms.map((x) => `${x.header.frame_id}->${x.child_frame_id}`).sort();
    if (pairs.join(",") !== "map->dead_reckoning/map,map->pf/map") fail(`/live/alignments: ${pairs}`);
    for (const x of m.transforms) {
      const { translation: p, rotation: q } = x.transform;
      if (p.x !== 0 || p.y !== 0 || q.w !== 1) fail(`/live/alignments: not the identity`);
    }
  } else if (topic === "/tf") {
    if (!m.transforms.every((x) => finite(x.transform.translation.x, x.transform.rotation.w))) {
      fail("/tf: not finite");
    }
  }
}

async function watch() {
  const client = new FoxgloveClient({
    ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
  });
  const channels = new Map();  // id -> channel
  const subs = new Map();      // subscription id -> { topic, reader }
  const topicSub = new Map();  // topic -> subscription id
  const counts = new Map();
  const state = { lastTime: new Map() };
  const samples = [];          // [wall ms, log time ns] of /clock messages
  let info = null;
  let paceReply = null;
  let lastClockTime = -1n;
  let unsubscribedAt = null;
  let scansAfter = 0;
  let closed = false;
  let firstClock = null;       // log time (ns) of the first /clock message

  const subscribe = (c) => {
    if (topicSub.has(c.topic)) return;
    if (c.encoding !== "cdr" || c.schemaEncoding !== "ros2msg") fail(`${c.topic}: ${c.encoding}/${c.schemaEncoding}`);
    if (!expectedTypes[c.topic].includes(c.schemaName)) fail(`${c.topic}: type ${c.schemaName}`);
    const reader = new MessageReader(parse(c.schema, { ros2: true }));
    const id = client.subscribe(c.id);
    subs.set(id, { topic: c.topic, reader });
    topicSub.set(c.topic, id);
  };
  client.on("serverInfo", (i) => { info = i; });
  client.on("status", (s) => fail(`status from the server: ${s.message}`));
  client.on("advertise", (list) => {
    for (const c of list) {
      channels.set(c.id, c);
      if (c.topic in expectedTypes && !latched.includes(c.topic)) subscribe(c);
    }
  });
  let timeFrames = 0;
  client.on("time", ({ timestamp }) => {
    ++timeFrames;
    if (timestamp < lastClockTime) fail(`time ${timestamp} after ${lastClockTime}`);
    lastClockTime = timestamp;
  });
  client.on("parameterValues", (v) => { if (v.id === "pace") paceReply = v.parameters; });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const s = subs.get(subscriptionId);
    if (!s) {
      fail(`a message for subscription ${subscriptionId}, which is not one`);
      return;
    }
    if (s.topic === "/scan" && unsubscribedAt !== null && Date.now() > unsubscribedAt + 1000) ++scansAfter;
    let m;
    try {
      m = s.reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    } catch (e) {
      fail(`${s.topic}: cannot decode: ${e.message}`);
      return;
    }
    counts.set(s.topic, (counts.get(s.topic) ?? 0) + 1);
    checkMessage(s.topic, m, timestamp, state);
    if (s.topic === "/clock") {
      if (firstClock === null) firstClock = timestamp;
      samples.push([Date.now(), Number(timestamp)]);
    }
  });
  client.on("close", () => { closed = true; });
  client.on("error", (e) => fail(`client error: ${e.message ?? e}`));

  // Until the run has advertised its topics, then /tf_static late: only its latched copy comes.
  for (let i = 0; i < 200 && ![...channels.values()].some((c) => c.topic === "/pf/map"); ++i) await sleep(50);
  if (!info) fail("no serverInfo");
  else {
    for (const cap of ["parameters", "time"]) {
      if (!info.capabilities.includes(cap)) fail(`serverInfo: no capability ${cap}`);
    }
  }
  await sleep(1000);
  for (const topic of latched) {
    const c = [...channels.values()].find((x) => x.topic === topic);
    if (!c) fail(`${topic} not advertised`);
    else subscribe(c);
  }

  // The run at twice real time while we watch.
  client.setParameters([{ name: "slamrig.pace", value: 2 }], "pace");
  await sleep(800);
  const from = samples.length;
  await sleep(3000);
  const window = samples.slice(from);
  if (!paceReply || paceReply[0]?.name !== "slamrig.pace" || paceReply[0]?.value !== 2) {
    fail(`setParameters slamrig.pace: reply ${JSON.stringify(paceReply)}`);
  }
  if (window.length < 10) {
    fail(`only ${window.length} /clock messages in 3 s at pace 2`);
  } else {
    const wall = (window.at(-1)[0] - window[0][0]) / 1000;
    const run = (window.at(-1)[1] - window[0][1]) / 1e9;
    console.log(`live_check: at pace 2: ${run.toFixed(2)} s of run time in ${wall.toFixed(2)} s of wall time`);
    if (run > 2 * wall * 1.2 + 0.2) fail(`pace 2: ${run} s of run time in ${wall} s`);
    if (run < 0.5) fail(`pace 2: the run hardly advanced (${run} s in ${wall} s)`);
  }

  // /scan stops after its unsubscription.
  client.unsubscribe(topicSub.get("/scan"));
  unsubscribedAt = Date.now();
  await sleep(2000);
  if (scansAfter > 0) fail(`${scansAfter} /scan messages more than 1 s after the unsubscription`);

  for (const topic of Object.keys(expectedTypes)) {
    if (!(counts.get(topic) > 0)) fail(`no ${topic} message received`);
  }
  for (const topic of latched) {
    if ((counts.get(topic) ?? 0) !== 1) fail(`${counts.get(topic)} ${topic} messages, expected its latched one`);
  }
  if (timeFrames < 100) fail(`only ${timeFrames} time frames`);
  if (closed) fail("the server closed the connection mid-run");
  if (option === "from-start" && !(firstClock !== null && firstClock <= 1000000000n)) {
    fail(`the first /clock at ${firstClock} ns: the run did not wait for this client`);
  }
  const summary = [...counts].map(([t, n]) => `${t} ${n}`).join(", ");
  client.close();  // mid-run: the run must go on
  clearTimeout(giveUp);
  if (errors.length > 0) {
    for (const e of errors.slice(0, 30)) console.error(`live_check: ${e}`);
    console.error(`live_check: ${errors.length} failures`);
    process.exit(1);
  }
  console.log(`live_check: decoded ${summary}; ${timeFrames} time frames`);
  process.exit(0);
}

if (mode === "watch") await watch();
else if (mode === "stall") stall();
else {
  console.error(`live_check: unknown mode ${mode}`);
  process.exit(2);
}
