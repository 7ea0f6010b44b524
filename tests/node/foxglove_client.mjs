// An independent reader for posed's Foxglove server: the npm package @foxglove/ws-protocol's
// FoxgloveClient (the code Foxglove publishes for its protocol) over the `ws` WebSocket package,
// since Node 20 has no WebSocket client of its own. It subscribes to every advertised channel
// and, after --messages messages in all or --seconds seconds, prints one JSON line:
//
//   {"serverInfo":{...},"statuses":[...],"timedOut":false,"channels":{"/posed/odom":{"id":1,
//    "encoding":"cdr","schemaName":"...","schemaEncoding":"ros2msg","schemaBytes":123,
//    "messages":300,"bytes":210000,"fnv1a":"deadbeef","firstLogTimeNs":"...",
//    "lastLogTimeNs":"..."}}}
//
// bytes are payload bytes; fnv1a is FNV-1a (32 bit) over each channel's payloads in arrival
// order, so the test compares contents without shipping them. Exit status 0 when the report was
// printed (timed out or not), 2 when the connection failed or closed early.
//
// --decode parses each ros2msg schema with @foxglove/rosmsg and decodes every message with
// @foxglove/rosmsg2-serialization, as Foxglove Studio does: per channel "decoded" and
// "decodeErrors" (with the first error), and "last" holding a few fields of the newest message
// (header.frame_id; a PointCloud2's width, point_step and field names; a TFMessage's frames; a
// Status's mapping.state).
// --until-close reports when the server closes the connection (the end of a replay) and exits
// 0, instead of treating it as a failure.
//
// Usage: node foxglove_client.mjs ws://127.0.0.1:8765 [--messages N] [--seconds S] [--decode]
//                                 [--until-close]
// Run by tests/unit/foxglove/node_client_test.cpp; installed by tools/install-deps (npm ci).

import { parse as parseRosmsg } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

function parseArgs(argv) {
  const options = { url: undefined, messages: Infinity, seconds: 10, decode: false, untilClose: false };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === "--messages") options.messages = Number(argv[++i]);
    else if (argv[i] === "--seconds") options.seconds = Number(argv[++i]);
    else if (argv[i] === "--decode") options.decode = true;
    else if (argv[i] === "--until-close") options.untilClose = true;
    else options.url = argv[i];
  }
  if (!options.url || !(options.messages > 0) || !(options.seconds > 0)) {
    console.error(
      "usage: node foxglove_client.mjs URL [--messages N] [--seconds S] [--decode] [--until-close]");
    process.exit(2);
  }
  return options;
}

/// A few fields of a decoded message, enough for a test to tell it is the right one.
function summarize(message) {
  const out = {};
  if (message?.header?.frame_id !== undefined) out.frameId = message.header.frame_id;
  if (message?.point_step !== undefined) {
    out.width = message.width;
    out.pointStep = message.point_step;
    out.fields = message.fields.map((f) => `${f.name}:${f.datatype}@${f.offset}`);
    out.dataBytes = message.data.length;
  }
  if (Array.isArray(message?.transforms)) {
    out.transforms = message.transforms.map((t) => `${t.header.frame_id}->${t.child_frame_id}`);
  }
  if (Array.isArray(message?.poses)) out.poses = message.poses.length;
  if (Array.isArray(message?.status)) out.statuses = message.status.map((d) => d.name);
  if (message?.mapping?.state !== undefined) out.mappingState = message.mapping.state;
  return out;
}

function fnv1a(hash, bytes) {
  for (let i = 0; i < bytes.length; ++i) {
    hash ^= bytes[i];
    hash = Math.imul(hash, 0x01000193) >>> 0;
  }
  return hash;
}

const options = parseArgs(process.argv.slice(2));
const report = { serverInfo: null, statuses: [], timedOut: false, channels: {} };
const channelsBySubscription = new Map();
const readers = new Map();  // report entry -> MessageReader (--decode)
let received = 0;
let finished = false;

const client = new FoxgloveClient({
  ws: new WebSocket(options.url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]),
});

function finish(exitCode) {
  if (finished) return;
  finished = true;
  for (const channel of Object.values(report.channels)) {
    channel.fnv1a = channel.fnv1a.toString(16).padStart(8, "0");
  }
  process.stdout.write(JSON.stringify(report) + "\n", () => process.exit(exitCode));
  client.close();
}

const timer = setTimeout(() => {
  report.timedOut = true;
  finish(0);
}, options.seconds * 1000);

client.on("serverInfo", (info) => {
  report.serverInfo = info;
});
client.on("status", (status) => {
  report.statuses.push(status);
});
client.on("advertise", (channels) => {
  for (const channel of channels) {
    report.channels[channel.topic] = {
      id: channel.id,
      encoding: channel.encoding,
      schemaName: channel.schemaName,
      schemaEncoding: channel.schemaEncoding,
      schemaBytes: Buffer.byteLength(channel.schema, "utf8"),
      messages: 0,
      bytes: 0,
      fnv1a: 0x811c9dc5,
      firstLogTimeNs: null,
      lastLogTimeNs: null,
    };
    if (options.decode) {
      const entry = report.channels[channel.topic];
      entry.decoded = 0;
      entry.decodeErrors = 0;
      try {
        if (channel.schemaEncoding !== "ros2msg") throw new Error(`schema encoding ${channel.schemaEncoding}`);
        readers.set(entry, new MessageReader(parseRosmsg(channel.schema, { ros2: true })));
      } catch (error) {
        entry.schemaError = String(error.message ?? error);
      }
    }
    channelsBySubscription.set(client.subscribe(channel.id), report.channels[channel.topic]);
  }
});
client.on("message", ({ subscriptionId, timestamp, data }) => {
  const channel = channelsBySubscription.get(subscriptionId);
  if (channel === undefined) {
    const message = `message for unknown subscription ${subscriptionId}`;
    report.statuses.push({ level: 2, message });
    return;
  }
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  channel.messages += 1;
  channel.bytes += bytes.length;
  channel.fnv1a = fnv1a(channel.fnv1a, bytes);
  channel.firstLogTimeNs ??= timestamp.toString();
  channel.lastLogTimeNs = timestamp.toString();
  const reader = options.decode ? readers.get(channel) : undefined;
  if (reader !== undefined) {
    try {
      channel.last = summarize(reader.readMessage(bytes));
      channel.decoded += 1;
    } catch (error) {
      channel.decodeErrors += 1;
      channel.firstDecodeError ??= String(error.message ?? error);
    }
  }
  if (++received >= options.messages) {
    clearTimeout(timer);
    finish(0);
  }
});
client.on("error", (error) => {
  console.error(`foxglove_client: ${options.url}: ${error.message}`);
});
client.on("close", (event) => {
  if (finished) return;
  clearTimeout(timer);
  if (options.untilClose) {
    report.closedByServer = true;
    finish(0);
    return;
  }
  console.error(`foxglove_client: ${options.url}: connection closed (code ${event.code})`);
  finish(2);
});
