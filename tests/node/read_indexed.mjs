// Read MCAP files the way Foxglove and Lichtblick open them: by the index (@mcap/core's
// McapIndexedReader, chunks decompressed by @mcap/support), every message decoded with its
// channel's schema (protobuf through protobufjs from the file's FileDescriptorSet, JSON validated
// against the file's JSON Schema with Ajv). Prints one JSON object per file on stdout:
// {file, messages, topics: {topic: count}, schemas: {topic: name}, attachments, chunks,
//  crcChecked, logTimesOrdered, firstFrameMs, seekMs, errors: [...]}.
// Usage: node read_indexed.mjs FILE [FILE ...]
import { open } from "node:fs/promises";
import { performance } from "node:perf_hooks";

import { McapIndexedReader } from "@mcap/core";
import { loadDecompressHandlers, protobufFromBinaryDescriptor } from "@mcap/support";
import Ajv2020 from "ajv/dist/2020.js";

class FileReadable {
  constructor(handle) {
    this.handle = handle;
  }
  async size() {
    return BigInt((await this.handle.stat()).size);
  }
  async read(offset, size) {
    const buffer = new Uint8Array(Number(size));
    await this.handle.read(buffer, 0, Number(size), Number(offset));
    return buffer;
  }
}

const decompressHandlers = await loadDecompressHandlers();

function decoderFor(channel, schema, ajv) {
  if (channel.messageEncoding === "protobuf") {
    if (!schema || schema.encoding !== "protobuf") throw new Error(`${channel.topic}: protobuf channel without a protobuf schema`);
    const type = protobufFromBinaryDescriptor(schema.data).lookupType(schema.name);
    return (data) => type.toObject(type.decode(data), { longs: String, bytes: Buffer });
  }
  if (channel.messageEncoding === "json") {
    if (!schema || schema.encoding !== "jsonschema") throw new Error(`${channel.topic}: json channel without a JSON schema`);
    const validate = ajv.compile(JSON.parse(new TextDecoder().decode(schema.data)));
    return (data) => {
      const value = JSON.parse(new TextDecoder().decode(data));
      if (!validate(value)) throw new Error(ajv.errorsText(validate.errors));
      return value;
    };
  }
  throw new Error(`${channel.topic}: unknown message encoding ${channel.messageEncoding}`);
}

async function readFile(file) {
  const handle = await open(file, "r");
  const result = { file, messages: 0, topics: {}, schemas: {}, attachments: [], chunks: 0, errors: [] };
  try {
    const started = performance.now();
    const reader = await McapIndexedReader.Initialize({ readable: new FileReadable(handle), decompressHandlers });
    result.chunks = reader.chunkIndexes.length;
    const ajv = new Ajv2020({ strict: false, allErrors: false });
    const decoders = new Map();
    for (const [id, channel] of reader.channelsById) {
      const schema = reader.schemasById.get(channel.schemaId);
      result.schemas[channel.topic] = schema ? schema.name : null;
      try {
        decoders.set(id, decoderFor(channel, schema, ajv));
      } catch (error) {
        result.errors.push(String(error.message ?? error));
      }
    }
    const video = [...reader.channelsById.values()].find((c) => c.topic === "/camera/video" || c.topic === "/camera/image/compressed");
    if (video) {
      for await (const message of reader.readMessages({ topics: [video.topic] })) {
        decoders.get(message.channelId)?.(message.data);
        result.firstFrameMs = performance.now() - started;
        break;
      }
    }
    let last = -1n;
    result.logTimesOrdered = true;
    for await (const message of reader.readMessages({ validateCrcs: true })) {
      const channel = reader.channelsById.get(message.channelId);
      result.messages += 1;
      result.topics[channel.topic] = (result.topics[channel.topic] ?? 0) + 1;
      if (message.logTime < last) result.logTimesOrdered = false;
      last = message.logTime;
      const decode = decoders.get(message.channelId);
      if (!decode) continue;
      try {
        decode(message.data);
      } catch (error) {
        if (result.errors.length < 20) result.errors.push(`${channel.topic} message ${message.sequence}: ${error.message ?? error}`);
      }
    }
    result.crcChecked = true;
    if (reader.statistics && last >= 0n) {
      const { messageStartTime: start, messageEndTime: end } = reader.statistics;
      const t = start + (end - start) / 2n;
      const seekStarted = performance.now();
      for await (const message of reader.readMessages({ startTime: t })) {
        result.seekLogTime = String(message.logTime);
        break;
      }
      result.seekMs = performance.now() - seekStarted;
      result.seekTarget = String(t);
    }
    for await (const attachment of reader.readAttachments()) {
      result.attachments.push({ name: attachment.name, mediaType: attachment.mediaType, bytes: attachment.data.byteLength });
    }
  } catch (error) {
    result.errors.push(String(error.message ?? error));
  } finally {
    await handle.close();
  }
  return result;
}

for (const file of process.argv.slice(2)) {
  console.log(JSON.stringify(await readFile(file)));
}
