// Reads an MCAP file with the official TypeScript MCAP library (@mcap/core, from npm), independently
// of bvc3d: once record by record (McapStreamReader, CRCs checked) and once through the summary and
// indexes (McapIndexedReader, messages in log-time order, chunk CRCs checked). Prints JSON: each
// read's messages as [topic, log time (ns, as a string), sha256 of the data], the summary's counts.
// Chunks compressed with zstd are decompressed by Debian's `zstd` program (Node 20 has no zstd).
// Usage: node test/js/read_mcap.mjs FILE.mcap
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { execFileSync } from "node:child_process";
import { createHash } from "node:crypto";
import { readFileSync } from "node:fs";

const decompressHandlers = {
  zstd: (data, size) => {
    const out = execFileSync("zstd", ["-d", "-q", "-c"], { input: data, maxBuffer: Number(size) + 1024 });
    if (BigInt(out.length) !== size) throw new Error(`zstd gave ${out.length} bytes, the chunk declares ${size}`);
    return new Uint8Array(out.buffer, out.byteOffset, out.length);
  },
};
const sha = (data) => createHash("sha256").update(data).digest("hex");

const bytes = readFileSync(process.argv[2]);

const stream = [];
const streamReader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
streamReader.append(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.length));
const topicOf = new Map();
for (let r; (r = streamReader.nextRecord()); ) {
  if (r.type === "Channel") topicOf.set(r.id, r.topic);
  if (r.type === "Message") stream.push([topicOf.get(r.channelId), r.logTime.toString(), sha(r.data)]);
}
if (!streamReader.done()) throw new Error("the stream reader did not reach the end of the file");

const readable = {
  size: async () => BigInt(bytes.length),
  read: async (offset, size) => new Uint8Array(bytes.buffer, bytes.byteOffset + Number(offset), Number(size)),
};
const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
const indexed = [];
for await (const m of reader.readMessages({ validateCrcs: true })) {
  indexed.push([reader.channelsById.get(m.channelId).topic, m.logTime.toString(), sha(m.data)]);
}
const channels = [...reader.channelsById.values()].map((c) => ({
  topic: c.topic,
  encoding: c.messageEncoding,
  schema: reader.schemasById.get(c.schemaId)?.name,
  schemaEncoding: reader.schemasById.get(c.schemaId)?.encoding,
  metadata: Object.fromEntries(c.metadata),
}));
const s = reader.statistics;
console.log(
  JSON.stringify({
    profile: reader.header.profile,
    stream,
    indexed,
    channels,
    chunks: reader.chunkIndexes.length,
    statistics: s && {
      messageCount: Number(s.messageCount),
      chunkCount: s.chunkCount,
      channelCount: s.channelCount,
      schemaCount: s.schemaCount,
      messageStartTime: s.messageStartTime.toString(),
      messageEndTime: s.messageEndTime.toString(),
      channelMessageCounts: Object.fromEntries([...s.channelMessageCounts].map(([k, v]) => [k, Number(v)])),
    },
  }),
);
