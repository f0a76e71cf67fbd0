// Time an indexed open and seeks the way a Foxglove player does them, with @mcap/core (for bench/):
// open the file by its summary and read its first video frame; then, for each of N times spread over
// the recording, read the video frames of the 2 s before it (a keyframe interval: what decoding the
// frame at that time needs) and the first message of every topic at or after it.
// Usage: node open_and_seek.mjs FILE [N]; prints {openMs, firstFrameMs, seekMs: [...], messagesPerSeek}.
import { open } from "node:fs/promises";
import { performance } from "node:perf_hooks";

import { McapIndexedReader } from "@mcap/core";
import { loadDecompressHandlers } from "@mcap/support";

const [file, n = "20"] = process.argv.slice(2);
const handle = await open(file, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, size) => {
    const buffer = new Uint8Array(Number(size));
    await handle.read(buffer, 0, Number(size), Number(offset));
    return buffer;
  },
};
const decompressHandlers = await loadDecompressHandlers();
const started = performance.now();
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const openMs = performance.now() - started;
const video = [...reader.channelsById.values()].find((c) => c.topic === "/camera/video" || c.topic === "/camera/image/compressed");
let firstFrameMs = null;
for await (const _ of reader.readMessages({ topics: [video.topic] })) {
  firstFrameMs = performance.now() - started;
  break;
}
const { messageStartTime: start, messageEndTime: end } = reader.statistics;
const seekMs = [];
let messages = 0;
for (let k = 0; k < Number(n); k++) {
  const t = start + ((end - start) * BigInt(2 * k + 1)) / BigInt(2 * Number(n));
  const t0 = performance.now();
  for await (const _ of reader.readMessages({ topics: [video.topic], startTime: t - 2_000_000_000n, endTime: t })) messages += 1;
  const seen = new Set();
  for await (const message of reader.readMessages({ startTime: t })) {
    seen.add(message.channelId);
    messages += 1;
    if (seen.size === reader.channelsById.size || message.logTime > t + 2_000_000_000n) break;
  }
  seekMs.push(performance.now() - t0);
}
await handle.close();
console.log(JSON.stringify({ openMs, firstFrameMs, seekMs, messagesPerSeek: messages / Number(n) }));
