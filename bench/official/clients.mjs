// The official clients, from npm, against appmode (issue 78): @foxglove/ws-protocol's
// FoxgloveClient drives and tunes a live session; @mcap/core's McapIndexedReader reads a
// recording through its index. Run by bench/official_clients.py; prints one JSON line.
//   node clients.mjs drive WS_URL      node clients.mjs mcap FILE
import { createRequire } from "node:module";
import { open } from "node:fs/promises";

const require = createRequire(process.cwd() + "/");
const { FoxgloveClient } = require("@foxglove/ws-protocol");
const { McapIndexedReader } = require("@mcap/core");
const WebSocket = require("ws");

const [mode, target] = process.argv.slice(2);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

async function drive(url) {
  // The SDK's server speaks the protocol as foxglove.sdk.v1 (the same protocol under its
  // new name; FoxgloveClient takes the subprotocol its WebSocket asks for, as Foxglove's
  // app does: foxglove.websocket.v1 alone is refused with a 400).
  const client = new FoxgloveClient({ ws: new WebSocket(url, ["foxglove.sdk.v1"]) });
  const said = { capabilities: [], answers: {}, updates: [], status: [] };
  const info = new Promise((resolve) => client.on("serverInfo", resolve));
  client.on("parameterValues", (event) => {
    if (event.id) said.answers[event.id] = event.parameters;
    else said.updates.push(event.parameters);
  });
  client.on("status", (event) => said.status.push(event.message));
  said.capabilities = (await info).capabilities;
  let listed = [];
  for (let attempt = 0; attempt < 40 && listed.length === 0; attempt++) {
    client.getParameters([], `get${attempt}`);
    await sleep(250);
    listed = said.answers[`get${attempt}`] ?? [];
  }
  said.listed = listed.map((p) => p.name);
  const channel = client.advertise({
    topic: "/cmd_vel",
    encoding: "json",
    schemaName: "geometry_msgs/msg/Twist",
  });
  const twist = { linear: { x: 0.3, y: 0, z: 0 }, angular: { x: 0, y: 0, z: 0 } };
  const data = new TextEncoder().encode(JSON.stringify(twist));
  const start = Date.now();
  while (Date.now() - start < 2000) {
    client.sendMessage(channel, data);
    said.last = Date.now() / 1000;
    await sleep(100);
  }
  await sleep(1500); // the lapse stops the car, not the viewer leaving
  client.subscribeParameterUpdates(said.listed);
  client.setParameters([{ name: "max_speed", value: 800 }], "set");
  for (let wait = 0; wait < 40; wait++) {
    if (said.updates.some((u) => u.some((p) => p.name === "max_speed" && p.value === 800))) break;
    await sleep(200);
  }
  client.close();
  return said;
}

async function readMcap(path) {
  const handle = await open(path, "r");
  const size = BigInt((await handle.stat()).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const buffer = new Uint8Array(Number(length));
      await handle.read(buffer, 0, Number(length), Number(offset));
      return buffer;
    },
  };
  const zstd = require("@foxglove/wasm-zstd");
  await zstd.isLoaded;
  const reader = await McapIndexedReader.Initialize({
    readable,
    decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) },
  });
  const topics = {};
  let first = null;
  let last = null;
  let count = 0;
  for await (const message of reader.readMessages()) {
    const topic = reader.channelsById.get(message.channelId).topic;
    topics[topic] = (topics[topic] ?? 0) + 1;
    first = first === null || message.logTime < first ? message.logTime : first;
    last = last === null || message.logTime > last ? message.logTime : last;
    count++;
  }
  const schemaless = [...reader.channelsById.values()].filter((c) => c.schemaId === 0);
  await handle.close();
  return {
    count,
    statistics: Number(reader.statistics?.messageCount ?? -1),
    chunks: reader.chunkIndexes.length,
    first: Number(first) / 1e9,
    last: Number(last) / 1e9,
    topics,
    schemaless: schemaless.map((c) => c.topic),
  };
}

const result = mode === "drive" ? await drive(target) : await readMcap(target);
console.log(JSON.stringify(result));
process.exit(0);
