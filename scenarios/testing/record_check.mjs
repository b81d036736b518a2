// Independent check of a recorded run (slamrig run --record) with Foxglove's own readers
// (@mcap/core, @mcap/support, @foxglove/rosmsg, @foxglove/rosmsg2-serialization): every message
// of run.mcap is decoded twice, with the schema the file carries and with Foxglove's reference
// ROS 2 Humble definitions (@foxglove/rosmsg-msgs-common), and both must agree. Then the topics,
// their types and counts against the report folder's files, the clock order (log times per
// topic in file order, header stamps) and /<config>/pose against <config>.tum (or
// <config>_online.tum where the estimator revised its past), value for value.
//
// Usage: node record_check.mjs NODE_MODULES_PARENT full REPORT_DIR [LAYOUT]
//        node record_check.mjs NODE_MODULES_PARENT partial FILE
// `partial`: FILE is what a killed run left (run.mcap.partial): the indexed reader must refuse
// it (no summary, no footer: it does not look complete), and the stream reader must decode
// every whole record up to the cut.
// LAYOUT (foxglove/slamrig.json): every topic a panel names that belongs to this run's
// configurations (or to no configuration) is in the file with a type the panel shows, and every
// plotted path reads a number from its messages.
// Exit 0 when everything holds; otherwise one line per failure (first 30) and exit 1.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const [, , modulesParent, mode, target, layoutPath] = process.argv;
const require = createRequire(path.join(path.resolve(modulesParent), "package.json"));
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { FileHandleReadable } = require("@mcap/nodejs");
const { loadDecompressHandlers } = require("@mcap/support");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const { ros2humble } = require("@foxglove/rosmsg-msgs-common");

const decompressHandlers = await loadDecompressHandlers();
const errors = [];
const fail = (msg) => errors.push(msg);
const finish = (summary) => {
  if (errors.length > 0) {
    for (const e of errors.slice(0, 30)) console.error(`record_check: ${e}`);
    console.error(`record_check: ${errors.length} failures`);
    process.exit(1);
  }
  console.log(`record_check: ${summary}`);
  process.exit(0);
};

// Readers per schema: the file's own definition, and Foxglove's reference one.
const fileReaders = new Map();
const referenceReaders = new Map();
function readersFor(schema) {
  if (!fileReaders.has(schema.id)) {
    if (schema.encoding !== "ros2msg") fail(`schema ${schema.name}: encoding ${schema.encoding}`);
    const text = new TextDecoder().decode(schema.data);
    fileReaders.set(schema.id, new MessageReader(parse(text, { ros2: true })));
    const short = schema.name.replace("/msg/", "/");
    const ref = ros2humble[short];
    if (!ref) {
      fail(`schema ${schema.name}: not a ROS 2 Humble type Foxglove knows`);
      referenceReaders.set(schema.id, null);
    } else {
      // The reference definition with every type it depends on.
      const defs = [ref];
      const seen = new Set([short]);
      for (let i = 0; i < defs.length; ++i) {
        for (const f of defs[i].definitions) {
          if (!f.isComplex || seen.has(f.type)) continue;
          seen.add(f.type);
          defs.push({ ...ros2humble[f.type], name: f.type });
        }
      }
      referenceReaders.set(schema.id, new MessageReader(defs, { timeType: "sec,nanosec" }));
    }
  }
  return [fileReaders.get(schema.id), referenceReaders.get(schema.id)];
}

function plain(v) {
  if (ArrayBuffer.isView(v)) return Array.from(v);
  if (Array.isArray(v)) return v.map(plain);
  if (typeof v === "bigint") return Number(v);
  if (v !== null && typeof v === "object") {
    const o = {};
    for (const [k, x] of Object.entries(v)) o[k === "nsec" ? "nanosec" : k] = plain(x);
    return o;
  }
  return v;
}

const stampNs = (s) => BigInt(s.sec) * 1000000000n + BigInt(s.nanosec ?? s.nsec);

// Decodes one message both ways; returns the decoded value (or undefined after a failure).
function decode(schema, channel, data, where) {
  const [own, reference] = readersFor(schema);
  let msg;
  try {
    msg = own.readMessage(data);
  } catch (e) {
    fail(`${where} (${channel.topic}): ${e.message}`);
    return undefined;
  }
  if (reference) {
    try {
      const a = JSON.stringify(plain(msg));
      const b = JSON.stringify(plain(reference.readMessage(data)));
      if (a !== b) fail(`${where} (${channel.topic}): the reference definition reads it otherwise`);
    } catch (e) {
      fail(`${where} (${channel.topic}): reference reader: ${e.message}`);
    }
  }
  return msg;
}

// The stamp a message carries, where it has one.
function headerStamp(msg) {
  if (msg?.header?.stamp) return stampNs(msg.header.stamp);
  if (msg?.transforms) {
    const stamps = new Set(msg.transforms.map((t) => stampNs(t.header.stamp)));
    return stamps.size === 1 ? [...stamps][0] : undefined;
  }
  if (msg?.clock) return stampNs(msg.clock);
  return undefined;
}

if (mode === "partial") {
  const bytes = fs.readFileSync(target);
  const handle = await fs.promises.open(target, "r");
  let refused = false;
  try {
    await McapIndexedReader.Initialize({ readable: new FileHandleReadable(handle), decompressHandlers });
  } catch {
    refused = true;
  }
  if (!refused) fail(`${target}: the indexed reader opened it: it looks complete`);
  const magic = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);
  if (bytes.length >= 8 && bytes.subarray(bytes.length - 8).equals(magic)) {
    fail(`${target}: ends with the closing magic`);
  }
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(bytes);
  const schemas = new Map();
  const channels = new Map();
  let messages = 0;
  let footer = false;
  for (let record; (record = reader.nextRecord()); ) {
    if (record.type === "Schema") schemas.set(record.id, record);
    else if (record.type === "Channel") channels.set(record.id, record);
    else if (record.type === "Footer" || record.type === "DataEnd") footer = true;
    else if (record.type === "Message") {
      const channel = channels.get(record.channelId);
      decode(schemas.get(channel.schemaId), channel, record.data, `message ${messages}`);
      ++messages;
    }
  }
  if (footer) fail(`${target}: has a DataEnd or Footer record`);
  if (reader.done()) fail(`${target}: the stream reader finished it: it looks complete`);
  if (messages === 0) fail(`${target}: no message before the cut`);
  finish(`${target}: cut short, refused by the indexed reader, ${messages} messages decoded up to the cut`);
}

// A whole run.
const dir = target;
const file = path.join(dir, "run.mcap");
const handle = await fs.promises.open(file, "r");
const reader = await McapIndexedReader.Initialize({ readable: new FileHandleReadable(handle), decompressHandlers });
if (reader.header.profile !== "ros2") fail(`profile '${reader.header.profile}'`);
const metrics = JSON.parse(fs.readFileSync(path.join(dir, "metrics.json"), "utf8"));
const configs = Object.keys(metrics.configs);

function readTum(name) {
  const p = path.join(dir, name);
  if (!fs.existsSync(p)) return null;
  return fs.readFileSync(p, "utf8").split("\n").filter((l) => l && !l.startsWith("#")).map((l) => {
    const f = l.split(" ");
    const [s, ns] = f[0].split(".");
    return { ns: BigInt(s) * 1000000000n + BigInt(ns), x: Number(f[1]), y: Number(f[2]), qz: Number(f[6]), qw: Number(f[7]) };
  });
}

// Every message, in the reader's (log time) order; per topic: count, type, values kept where
// they are checked below.
const topics = new Map();
const lastInFile = new Map();
let previous = -1n;
let total = 0;
for await (const m of reader.readMessages()) {
  const channel = reader.channelsById.get(m.channelId);
  const schema = reader.schemasById.get(channel.schemaId);
  if (channel.messageEncoding !== "cdr") fail(`${channel.topic}: encoding ${channel.messageEncoding}`);
  const where = `message ${total}`;
  ++total;
  if (m.logTime < previous) fail(`${where} (${channel.topic}): log time goes back`);
  previous = m.logTime;
  if (m.publishTime !== m.logTime) fail(`${where} (${channel.topic}): publish time != log time`);
  const msg = decode(schema, channel, m.data, where);
  const t = topics.get(channel.topic) ?? { type: schema.name, count: 0, msgs: [] };
  t.count++;
  const stamp = headerStamp(msg);
  if (stamp !== undefined && stamp !== m.logTime && !channel.topic.endsWith("/path")) {
    fail(`${where} (${channel.topic}): stamp ${stamp} != log time ${m.logTime}`);
  }
  if (/\/pose$|\/path$|^\/tf$|\/map$|\/error$|\/graph$/.test(channel.topic) || channel.topic === "/tf_static" ||
      t.msgs.length === 0) {
    t.msgs.push({ logTime: m.logTime, msg });
  }
  topics.set(channel.topic, t);
}

// Per topic, log times never go back in the file's own order (what a player streaming the file
// from the start sees): read every chunk in file order through the stream reader.
{
  const bytes = fs.readFileSync(file);
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  const channels = new Map();
  let n = 0;
  for (let record; (record = stream.nextRecord()); ) {
    if (record.type === "Channel") channels.set(record.id, record);
    if (record.type !== "Message") continue;
    ++n;
    const topic = channels.get(record.channelId).topic;
    const last = lastInFile.get(topic);
    if (last !== undefined && record.logTime < last) fail(`${topic}: log time goes back in file order at ${record.logTime}`);
    lastInFile.set(topic, record.logTime);
  }
  if (!stream.done()) fail("the stream reader did not reach the end");
  if (n !== total) fail(`stream reader: ${n} messages, indexed reader ${total}`);
}

// Statistics agree with what was read.
if (reader.statistics && Number(reader.statistics.messageCount) !== total) {
  fail(`statistics: ${reader.statistics.messageCount} messages, read ${total}`);
}

const expectType = (topic, type) => {
  const t = topics.get(topic);
  if (!t) return fail(`missing topic ${topic}`);
  if (t.type !== type) fail(`${topic}: type ${t.type}, expected ${type}`);
  return t;
};
const truth = readTum("truth.tum");
const scans = metrics.scans - metrics.scans_blacked_out;
const simTime = metrics.sim_time_s;
expectType("/scan", "sensor_msgs/msg/LaserScan");
if (topics.get("/scan")?.count !== scans) fail(`/scan: ${topics.get("/scan")?.count} messages, ${scans} scans`);
// A simulated robot has wheel encoders and an IMU; a log has what it has.
const simulated = metrics.source === "simulation";
if (simulated || topics.has("/odom")) expectType("/odom", "nav_msgs/msg/Odometry");
if (simulated || topics.has("/imu")) expectType("/imu", "sensor_msgs/msg/Imu");
if (simulated || topics.has("/joint_states")) expectType("/joint_states", "sensor_msgs/msg/JointState");
expectType("/clock", "rosgraph_msgs/msg/Clock");
expectType("/ground_truth/odom", "nav_msgs/msg/Odometry");
if (topics.get("/ground_truth/odom")?.count !== truth.length) fail(`/ground_truth/odom: not one per truth.tum line`);
expectType("/truth/map", "nav_msgs/msg/OccupancyGrid");
if (topics.get("/truth/map")?.count !== 1) fail(`/truth/map: ${topics.get("/truth/map")?.count} messages`);
expectType("/tf", "tf2_msgs/msg/TFMessage");
const tfStatic = expectType("/tf_static", "tf2_msgs/msg/TFMessage");

// /tf: map -> truth/base_link at every truth.tum pose, <config>/map -> <config>/base_link at
// every online pose.
const tfCounts = new Map();
for (const { msg } of topics.get("/tf").msgs) {
  for (const t of msg.transforms) {
    const key = `${t.header.frame_id}->${t.child_frame_id}`;
    tfCounts.set(key, (tfCounts.get(key) ?? 0) + 1);
  }
}
if (tfCounts.get("map->truth/base_link") !== truth.length) fail(`/tf map->truth/base_link: ${tfCounts.get("map->truth/base_link")} of ${truth.length}`);

// /tf_static: the last message holds base_link's mounts, truth/base_link -> base_link and the
// alignments map -> <config>/map.
const lastStatic = tfStatic?.msgs.at(-1)?.msg.transforms.map((t) => `${t.header.frame_id}->${t.child_frame_id}`) ?? [];
for (const want of ["truth/base_link->base_link", "base_link->laser", ...configs.map((c) => `map->${c}/map`)]) {
  if (!lastStatic.includes(want)) fail(`/tf_static: no ${want} (has ${lastStatic.join(", ")})`);
}

for (const c of configs) {
  const online = readTum(`${c}_online.tum`) ?? readTum(`${c}.tum`);
  const final = readTum(`${c}.tum`);
  const pose = topics.get(`/${c}/pose`);
  if (!pose) {
    fail(`missing /${c}/pose`);
    continue;
  }
  if (!["geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/PoseWithCovarianceStamped"].includes(pose.type)) fail(`/${c}/pose: type ${pose.type}`);
  if (pose.count !== online.length) fail(`/${c}/pose: ${pose.count} messages, ${online.length} poses in the .tum`);
  pose.msgs.forEach(({ logTime, msg }, i) => {
    const p = msg.pose.pose ?? msg.pose;
    const want = online[i];
    if (!want) return;
    if (msg.header.frame_id !== `${c}/map`) fail(`/${c}/pose[${i}]: frame ${msg.header.frame_id}`);
    if (logTime !== want.ns || p.position.x !== want.x || p.position.y !== want.y ||
        p.orientation.z !== want.qz || p.orientation.w !== want.qw) {
      fail(`/${c}/pose[${i}] at ${logTime}: (${p.position.x}, ${p.position.y}, ${p.orientation.z}, ${p.orientation.w}) != .tum (${want.ns}: ${want.x}, ${want.y}, ${want.qz}, ${want.qw})`);
    }
  });
  if (tfCounts.get(`${c}/map->${c}/base_link`) !== online.length) fail(`/tf ${c}/map->${c}/base_link: ${tfCounts.get(`${c}/map->${c}/base_link`)}`);
  const pathTopic = expectType(`/${c}/path`, "nav_msgs/msg/Path");
  const poses = pathTopic?.msgs.at(-1)?.msg.poses ?? [];
  if (pathTopic?.count !== 1 || poses.length !== final.length) fail(`/${c}/path: ${pathTopic?.count} messages, ${poses.length} poses of ${final.length}`);
  poses.forEach((p, i) => {
    if (p.pose.position.x !== final[i].x || p.pose.position.y !== final[i].y) fail(`/${c}/path[${i}] != ${c}.tum`);
  });
  const map = expectType(`/${c}/map`, "nav_msgs/msg/OccupancyGrid");
  // Every few seconds of run time (5 s) and once at the end.
  const wantMaps = Math.floor(simTime / 5);
  if (map && (map.count < wantMaps || map.count > wantMaps + 3)) fail(`/${c}/map: ${map.count} messages in ${simTime} s`);
  for (const { msg } of map?.msgs ?? []) {
    const g = msg;
    if (g.data.length !== g.info.width * g.info.height) fail(`/${c}/map: ${g.data.length} cells for ${g.info.width} x ${g.info.height}`);
    if (g.data.some((v) => v < -1 || v > 100)) fail(`/${c}/map: a value outside [-1, 100]`);
  }
  const error = expectType(`/${c}/error`, "geometry_msgs/msg/Vector3Stamped");
  if (error && error.count !== online.length) fail(`/${c}/error: ${error.count} messages for ${online.length} poses`);
  // The position error's RMS over the online poses is the online ATE (same alignment only when
  // the estimate is not revised; then exactly, to rounding).
  const m = metrics.configs[c];
  if (error && m.online_ate_rmse_m !== undefined && (readTum(`${c}_online.tum`) === null)) {
    const rms = Math.sqrt(error.msgs.reduce((a, { msg }) => a + msg.vector.x ** 2, 0) / error.count);
    if (Math.abs(rms - m.online_ate_rmse_m) > 1e-6 * Math.max(1, m.online_ate_rmse_m)) {
      fail(`/${c}/error: RMS position error ${rms} != online_ate_rmse_m ${m.online_ate_rmse_m}`);
    }
  }
  for (const [topic, t] of topics) {
    if (topic === `/${c}/particles`) expectType(topic, "geometry_msgs/msg/PoseArray");
    if (topic === `/${c}/graph` || topic === `/${c}/landmarks`) expectType(topic, "visualization_msgs/msg/MarkerArray");
    if (topic === `/${c}/graph` && m.rejected !== undefined) {
      // The last graph message carries every rejected candidate as one line.
      const last = t.msgs.at(-1)?.msg.markers.find((k) => k.ns === "rejected_loop_closures");
      const lines = (last?.points.length ?? 0) / 2;
      if (lines !== m.rejected) fail(`/${c}/graph: ${lines} rejected candidates drawn, ${m.rejected} in metrics.json`);
    }
    if (topic.startsWith(`/${c}/health/`)) {
      expectType(topic, "std_msgs/msg/Float64");
      if (t.count !== online.length) fail(`${topic}: ${t.count} messages for ${online.length} scans`);
    }
  }
}
// Every topic is one of the above.
const known = /^\/(scan|odom|imu|joint_states|clock|tf|tf_static|events|ground_truth\/odom|truth\/map|camera\/.*)$/;
for (const topic of topics.keys()) {
  const config = configs.find((c) => topic.startsWith(`/${c}/`));
  if (!known.test(topic) && !config) fail(`unexpected topic ${topic}`);
}
if (topics.has("/events")) expectType("/events", "std_msgs/msg/String");

if (layoutPath) {
  const layout = JSON.parse(fs.readFileSync(layoutPath, "utf8"));
  const panels = Object.keys(layout.configById);
  for (const kind of ["3D!", "Plot!", "Image!", "RawMessages!"]) {
    if (!panels.some((p) => p.startsWith(kind))) fail(`layout: no ${kind} panel`);
  }
  // A topic of a configuration this run does not have is for other scenarios.
  const ours = (topic) => {
    const first = topic.split("/")[1];
    const configTopic = !["scan", "truth", "events", "camera", "tf", "tf_static", "odom", "imu"].includes(first);
    return !configTopic || configs.includes(first);
  };
  const shown3d = ["nav_msgs/msg/OccupancyGrid", "sensor_msgs/msg/LaserScan", "geometry_msgs/msg/PoseStamped",
    "geometry_msgs/msg/PoseWithCovarianceStamped", "geometry_msgs/msg/PoseArray", "nav_msgs/msg/Path",
    "visualization_msgs/msg/MarkerArray"];
  let checked = 0;
  for (const [id, config] of Object.entries(layout.configById)) {
    if (id.startsWith("3D!")) {
      if (config.followTf !== "map") fail(`layout ${id}: display frame ${config.followTf}`);
      for (const topic of Object.keys(config.topics ?? {})) {
        if (!ours(topic)) continue;
        const t = topics.get(topic);
        if (!t) fail(`layout ${id}: ${topic} is not in the run`);
        else if (!shown3d.includes(t.type)) fail(`layout ${id}: ${topic} is a ${t.type}`);
        ++checked;
      }
    }
    for (const p of config.paths ?? []) {
      const [topic, ...fields] = p.value.split(".");
      if (!ours(topic)) continue;
      const t = topics.get(topic);
      if (!t) {
        fail(`layout ${id}: ${topic} is not in the run`);
        continue;
      }
      const value = fields.reduce((v, f) => v?.[f], t.msgs[0]?.msg);
      if (typeof value !== "number") fail(`layout ${id}: ${p.value} is not a number (${value})`);
      if (p.timestampMethod === "headerStamp" && !t.msgs[0]?.msg?.header) fail(`layout ${id}: ${topic} has no header`);
      ++checked;
    }
    const image = config.imageMode?.imageTopic;
    if (image && [...topics.keys()].some((t) => t.startsWith("/camera/"))) {
      if (topics.get(image)?.type !== "sensor_msgs/msg/Image") fail(`layout ${id}: ${image} is not an image of the run`);
      ++checked;
    }
    if (config.topicPath && ours(config.topicPath) && !topics.has(config.topicPath) && config.topicPath !== "/events") {
      fail(`layout ${id}: ${config.topicPath} is not in the run`);
    }
  }
  console.log(`record_check: layout ${layoutPath}: ${checked} topic references checked`);
}
const counts = [...topics].map(([t, v]) => `${t} ${v.count}`).join(", ");
finish(`${file}: ${total} messages decoded by both definitions; ${counts}`);
