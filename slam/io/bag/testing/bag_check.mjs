// Independent check of slamrig's ROS 2 bags with Foxglove's readers (@mcap/core, @foxglove/
// rosbag2-web, @foxglove/rosmsg, @foxglove/rosmsg2-serialization): every message of every topic
// is decoded and compared field by field with expected.json, which slamrig_write_test_bags
// wrote alongside. MCAP files are also checked for the data-section CRC, the summary CRC (the
// indexed reader validates it), chunk CRCs (validateCrcs), statistics, chunk and message indexes.
//
// Usage: node bag_check.mjs NODE_MODULES_PARENT BAG_ROOT
// Exit 0 when everything matches; otherwise one line per mismatch (first 20) and exit 1.
import fs from "node:fs";
import path from "node:path";
import { createRequire } from "node:module";

const [, , modulesParent, bagRoot] = process.argv;
const require = createRequire(path.join(path.resolve(modulesParent), "package.json"));
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const { FileHandleReadable } = require("@mcap/nodejs");
const { parse } = require("@foxglove/rosmsg");
const { MessageReader } = require("@foxglove/rosmsg2-serialization");
const { Rosbag2, SqliteSqljs, ROS2_TO_DEFINITIONS, ROS2_DEFINITIONS_ARRAY } =
  require("@foxglove/rosbag2-web");
const { crc32 } = require("@foxglove/crc");
const zstd = require("@foxglove/wasm-zstd");
const lz4 = require("@foxglove/wasm-lz4");
const yaml = require("js-yaml");

await zstd.isLoaded;
await lz4.isLoaded;
const decompressHandlers = {
  zstd: (buffer, size) => zstd.decompress(buffer, Number(size)),
  lz4: (buffer, size) => lz4(buffer, Number(size)),
};

const expected = JSON.parse(fs.readFileSync(path.join(bagRoot, "expected.json"), "utf8"));
const errors = [];
const fail = (msg) => errors.push(msg);
let compared = 0;

// Plain JSON-like value of a decoded message (typed arrays to arrays). rosbag2-web's reader
// names builtin_interfaces/Time's fields {sec, nsec} (rostime's convention; the wire is the
// same), so `nsec` is renamed back to the message definition's `nanosec`.
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

// Every field of `want` equals the same field of `got`, and `got` has no others.
function compare(got, want, where) {
  if (typeof want === "number") {
    if (got !== want) fail(`${where}: ${got} != ${want}`);
    return got === want;
  }
  if (Array.isArray(want)) {
    if (!Array.isArray(got) || got.length !== want.length) {
      fail(`${where}: length ${got?.length} != ${want.length}`);
      return false;
    }
    return want.every((w, i) => compare(got[i], w, `${where}[${i}]`));
  }
  if (want !== null && typeof want === "object") {
    const gk = Object.keys(got ?? {}).sort().join(",");
    const wk = Object.keys(want).sort().join(",");
    if (gk !== wk) {
      fail(`${where}: fields {${gk}} != {${wk}}`);
      return false;
    }
    return Object.keys(want).every((k) => compare(got[k], want[k], `${where}.${k}`));
  }
  if (got !== want) fail(`${where}: ${JSON.stringify(got)} != ${JSON.stringify(want)}`);
  return got === want;
}

function checkTopic(bag, topic, got) {
  const want = expected.topics[topic];
  if (!want) return fail(`${bag}: unexpected topic ${topic}`);
  if (got.length !== want.messages.length) {
    return fail(`${bag} ${topic}: ${got.length} messages, expected ${want.messages.length}`);
  }
  got.forEach((m, i) => {
    const where = `${bag} ${topic}[${i}]`;
    if (m.logTime !== BigInt(want.messages[i].log_time)) {
      fail(`${where}: log time ${m.logTime} != ${want.messages[i].log_time}`);
    }
    for (const [decoder, value] of Object.entries(m.values)) {
      compare(plain(value), want.messages[i].msg, `${where} (${decoder})`);
    }
    ++compared;
  });
}

function checkMetadata(bag, dir, storage) {
  const meta = yaml.load(fs.readFileSync(path.join(dir, "metadata.yaml"), "utf8"))
    .rosbag2_bagfile_information;
  if (meta.storage_identifier !== storage) fail(`${bag}: storage ${meta.storage_identifier}`);
  if (!(meta.version >= 5)) fail(`${bag}: metadata version ${meta.version}`);
  let total = 0;
  for (const t of meta.topics_with_message_count) {
    const want = expected.topics[t.topic_metadata.name];
    if (!want) fail(`${bag}: metadata lists unknown topic ${t.topic_metadata.name}`);
    else {
      if (t.message_count !== want.messages.length) fail(`${bag}: metadata count ${t.topic_metadata.name}`);
      if (t.topic_metadata.type !== want.type) fail(`${bag}: metadata type ${t.topic_metadata.name}`);
    }
    if (t.topic_metadata.serialization_format !== "cdr") fail(`${bag}: serialization_format`);
    total += t.message_count;
  }
  if (meta.topics_with_message_count.length !== Object.keys(expected.topics).length) {
    fail(`${bag}: metadata has ${meta.topics_with_message_count.length} topics`);
  }
  if (meta.message_count !== total) fail(`${bag}: metadata message_count ${meta.message_count}`);
  if (!fs.existsSync(path.join(dir, meta.relative_file_paths[0]))) fail(`${bag}: missing file`);
  return path.join(dir, meta.relative_file_paths[0]);
}

// The reference decoders of @foxglove/rosbag2 (ROS 2 common_interfaces definitions).
const referenceReaders = new Map();
function referenceReader(type) {
  if (!referenceReaders.has(type)) {
    const def = ROS2_TO_DEFINITIONS.get(type);
    if (!def) throw new Error(`no reference definition for ${type}`);
    referenceReaders.set(type, new MessageReader([def, ...ROS2_DEFINITIONS_ARRAY]));
  }
  return referenceReaders.get(type);
}

async function checkMcap(bag, file) {
  const bytes = fs.readFileSync(file);
  const handle = await fs.promises.open(file, "r");
  const reader = await McapIndexedReader.Initialize({
    readable: new FileHandleReadable(handle),
    decompressHandlers,
  });
  if (reader.header.profile !== "ros2") fail(`${bag}: profile '${reader.header.profile}'`);
  if (reader.footer.summaryCrc === 0) fail(`${bag}: no summary CRC`);
  if (reader.dataSectionCrc === undefined) fail(`${bag}: no data section CRC`);
  const dataCrc = crc32(bytes.subarray(0, Number(reader.dataEndOffset)));
  if (dataCrc !== reader.dataSectionCrc) fail(`${bag}: data CRC ${dataCrc} != ${reader.dataSectionCrc}`);
  if (reader.chunkIndexes.length < 2) fail(`${bag}: only ${reader.chunkIndexes.length} chunks`);
  // Each chunk index points at a Chunk record and at MessageIndex records of its channels.
  for (const ci of reader.chunkIndexes) {
    if (bytes[Number(ci.chunkStartOffset)] !== 0x06) fail(`${bag}: chunk index off target`);
    for (const [channel, offset] of ci.messageIndexOffsets) {
      const at = Number(offset);
      if (bytes[at] !== 0x07 || bytes.readUInt16LE(at + 9) !== channel) {
        fail(`${bag}: message index of channel ${channel} off target`);
      }
    }
  }
  const decoders = new Map();
  for (const [id, channel] of reader.channelsById) {
    const schema = reader.schemasById.get(channel.schemaId);
    if (channel.messageEncoding !== "cdr" || schema.encoding !== "ros2msg") {
      fail(`${bag}: ${channel.topic} encodings ${channel.messageEncoding}/${schema.encoding}`);
    }
    if (schema.name !== expected.topics[channel.topic]?.type) fail(`${bag}: schema ${schema.name}`);
    const text = new TextDecoder().decode(schema.data);
    decoders.set(id, {
      topic: channel.topic,
      own: new MessageReader(parse(text, { ros2: true })),
      reference: referenceReader(schema.name),
    });
  }
  const byTopic = {};
  let count = 0;
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    const d = decoders.get(m.channelId);
    (byTopic[d.topic] ??= []).push({
      logTime: m.logTime,
      values: {
        "bag schema": d.own.readMessage(m.data),
        "ros2 definitions": d.reference.readMessage(m.data),
      },
    });
    ++count;
  }
  await handle.close();
  const stats = reader.statistics;
  if (!stats || stats.messageCount !== BigInt(count)) fail(`${bag}: statistics message count`);
  for (const [id, n] of stats?.channelMessageCounts ?? []) {
    const topic = decoders.get(id).topic;
    if (Number(n) !== (byTopic[topic]?.length ?? 0)) fail(`${bag}: statistics count ${topic}`);
  }
  if (stats && stats.chunkCount !== reader.chunkIndexes.length) fail(`${bag}: chunk count`);
  // The streaming reader walks the whole file and checks every chunk's CRC.
  const stream = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  stream.append(bytes);
  let streamed = 0;
  let sawFooter = false;
  for (let r; (r = stream.nextRecord()); ) {
    if (r.type === "Message") ++streamed;
    if (r.type === "Footer") sawFooter = true;
  }
  if (!stream.done() || !sawFooter || streamed !== count) fail(`${bag}: stream read ${streamed}`);
  return byTopic;
}

async function checkSqlite(bag, file) {
  // sql.js would fetch() its wasm by URL; hand it the bytes instead.
  const wasm = require.resolve("@foxglove/sql.js/dist/sql-wasm.wasm");
  await SqliteSqljs.Initialize({ wasmBinary: fs.readFileSync(wasm) });
  const bagReader = new Rosbag2([new SqliteSqljs(new Uint8Array(fs.readFileSync(file)))]);
  await bagReader.open();
  const byTopic = {};
  for await (const m of bagReader.readMessages()) {
    const logTime = BigInt(m.timestamp.sec) * 1000000000n + BigInt(m.timestamp.nsec);
    (byTopic[m.topic.name] ??= []).push({ logTime, values: { "rosbag2-web": m.value } });
    if (m.topic.type !== expected.topics[m.topic.name]?.type) fail(`${bag}: type ${m.topic.type}`);
  }
  for (const t of await bagReader.readTopics()) {
    const qos = t.offeredQosProfiles[0];
    const latched = t.name === "/tf_static";
    if (!qos || qos.reliability !== 1 || qos.durability !== (latched ? 1 : 2)) {
      fail(`${bag}: QoS of ${t.name}`);
    }
  }
  await bagReader.close();
  return byTopic;
}

for (const bag of expected.bags) {
  const dir = path.join(bagRoot, bag);
  const storage = bag.startsWith("mcap") ? "mcap" : "sqlite3";
  const file = checkMetadata(bag, dir, storage);
  const byTopic = storage === "mcap" ? await checkMcap(bag, file) : await checkSqlite(bag, file);
  for (const topic of Object.keys(expected.topics)) checkTopic(bag, topic, byTopic[topic] ?? []);
  for (const topic of Object.keys(byTopic)) {
    if (!expected.topics[topic]) fail(`${bag}: unexpected topic ${topic}`);
  }
  const n = Object.values(byTopic).reduce((a, v) => a + v.length, 0);
  console.log(`${bag}: ${n} messages on ${Object.keys(byTopic).length} topics`);
}
if (errors.length > 0) {
  for (const e of errors.slice(0, 20)) console.error(e);
  console.error(`bag_check: ${errors.length} mismatches`);
  process.exit(1);
}
console.log(`bag_check: all ${compared} messages match in ${expected.bags.length} bags`);
