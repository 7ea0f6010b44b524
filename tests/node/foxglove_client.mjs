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
// Usage: node foxglove_client.mjs ws://127.0.0.1:8765 [--messages N] [--seconds S]
// Run by tests/unit/foxglove/node_client_test.cpp; installed by tools/install-deps (npm ci).

import wsProtocol from "@foxglove/ws-protocol";
import WebSocket from "ws";

const { FoxgloveClient } = wsProtocol;

function parseArgs(argv) {
  const options = { url: undefined, messages: Infinity, seconds: 10 };
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i] === "--messages") options.messages = Number(argv[++i]);
    else if (argv[i] === "--seconds") options.seconds = Number(argv[++i]);
    else options.url = argv[i];
  }
  if (!options.url || !(options.messages > 0) || !(options.seconds > 0)) {
    console.error("usage: node foxglove_client.mjs URL [--messages N] [--seconds S]");
    process.exit(2);
  }
  return options;
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
  console.error(`foxglove_client: ${options.url}: connection closed (code ${event.code})`);
  clearTimeout(timer);
  finish(2);
});
