// Foxglove's own tools, for tests/recording/test_foxglove_node.py:
//   node foxglove.mjs counts LOG.mcap     messages per topic, read with @mcap/core's
//                                         McapIndexedReader (what Foxglove uses on a file with
//                                         a summary): chunk indexes -> message indexes -> messages
//   node foxglove.mjs schemas NAME...     Foxglove's published JSON schemas (@foxglove/schemas)
// Prints one JSON object on stdout; exits 1 with the reader's error on stderr.
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import { FileHandleReadable } from "@mcap/nodejs";
import { loadDecompressHandlers } from "@mcap/support";
import jsonschemas from "@foxglove/schemas/jsonschema.js";

async function counts(path) {
  const handle = await open(path, "r");
  try {
    const reader = await McapIndexedReader.Initialize({
      readable: new FileHandleReadable(handle),
      decompressHandlers: await loadDecompressHandlers(),
    });
    const topics = {};
    for (const channel of reader.channelsById.values()) topics[channel.topic] = 0;
    let messages = 0;
    for await (const message of reader.readMessages()) {
      topics[reader.channelsById.get(message.channelId).topic] += 1;
      messages += 1;
    }
    const schemas = {};
    for (const channel of reader.channelsById.values()) {
      schemas[channel.topic] = reader.schemasById.get(channel.schemaId)?.name ?? "";
    }
    return { messages, topics, schemas };
  } finally {
    await handle.close();
  }
}

function schemas(names) {
  const out = {};
  for (const name of names) {
    const schema = jsonschemas[name.replace(/^foxglove\./, "")];
    if (!schema) throw new Error(`@foxglove/schemas has no ${name}`);
    out[name] = schema;
  }
  return out;
}

const [command, ...args] = process.argv.slice(2);
try {
  const result = command === "counts" ? await counts(args[0]) : schemas(args);
  process.stdout.write(JSON.stringify(result) + "\n");
} catch (err) {
  process.stderr.write(`${err instanceof Error ? err.message : err}\n`);
  process.exit(1);
}
