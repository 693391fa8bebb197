// Independent check of a Replica recording with the reference TypeScript MCAP library (@mcap/core):
// the file must open with the indexed reader and the streaming reader, CRCs validated, and the
// message counts per channel and the last decoded samples must equal what 'replica inspect --json'
// reported. Usage: node mcap_core_check.cjs FILE INSPECT_JSON. Needs NODE_PATH to hold @mcap/core and
// fzstd (a pure-JavaScript zstd decoder).
"use strict";
const fs = require("fs");
const { McapIndexedReader, McapStreamReader } = require("@mcap/core");
const fzstd = require("fzstd");

const [file, inspectPath] = process.argv.slice(2);
if (!file || !inspectPath) {
  console.error("usage: node mcap_core_check.cjs FILE INSPECT_JSON");
  process.exit(2);
}
const inspect = JSON.parse(fs.readFileSync(inspectPath, "utf8"));
const bytes = new Uint8Array(fs.readFileSync(file));
const decompressHandlers = {
  zstd: (buffer, size) => {
    const out = fzstd.decompress(buffer);
    if (BigInt(out.length) !== size) {
      throw new Error(`zstd chunk decompressed to ${out.length} bytes, expected ${size}`);
    }
    return out;
  },
};

let failures = 0;
// JSON text with object keys sorted, so that field order does not matter; numbers print in
// JavaScript's shortest round-trip form, so equal text means bit-identical doubles.
function canonical(v) {
  if (Array.isArray(v)) {
    return `[${v.map(canonical).join(",")}]`;
  }
  if (v !== null && typeof v === "object") {
    return `{${Object.keys(v).sort().map((k) => `${JSON.stringify(k)}:${canonical(v[k])}`).join(",")}}`;
  }
  return JSON.stringify(v);
}
function expectEqual(what, got, want) {
  const g = canonical(got);
  const w = canonical(want);
  if (g !== w) {
    const cut = (t) => (t.length > 300 ? `${t.slice(0, 300)}...` : t);
    console.error(`FAIL ${file}: ${what}: @mcap/core gives ${cut(g)}, replica inspect ${cut(w)}`);
    failures++;
  }
}

// Count and keep the last decoded message of each topic.
function tally(messages, channelsById) {
  const counts = {};
  const last = {};
  for (const m of messages) {
    const topic = channelsById.get(m.channelId).topic;
    counts[topic] = (counts[topic] || 0) + 1;
    last[topic] = JSON.parse(new TextDecoder().decode(m.data));
  }
  return { counts, last };
}

function compare(label, { counts, last }) {
  for (const [topic, ch] of Object.entries(inspect.channels)) {
    expectEqual(`${label} message count on ${topic}`, counts[topic] || 0, ch.count);
  }
  for (const topic of Object.keys(counts)) {
    if (!(topic in inspect.channels)) {
      expectEqual(`${label} unexpected topic ${topic}`, counts[topic], 0);
    }
  }
  // inspect's 'last' is the channel's whole message; these fields are checked.
  const pick = (obj, keys) => Object.fromEntries(keys.map((k) => [k, obj[k]]));
  if (inspect.tracker.last) {
    expectEqual(`${label} last /hal/tracker`, pick(last["/hal/tracker"], ["seq", "tracked", "eye"]),
                pick(inspect.tracker.last, ["seq", "tracked", "eye"]));
  }
  if (inspect.accel.last) {
    expectEqual(`${label} last /hal/accel`, pick(last["/hal/accel"], ["seq", "gravity"]),
                pick(inspect.accel.last, ["seq", "gravity"]));
  }
  if (inspect.spectrometer.last) {
    expectEqual(`${label} last /hal/spectrometer`,
                pick(last["/hal/spectrometer"], ["seq", "integration_time_us", "counts",
                                                 "wavelength_coeffs", "nonlinearity_coeffs"]),
                pick(inspect.spectrometer.last, ["seq", "integration_time_us", "counts",
                                                 "wavelength_coeffs", "nonlinearity_coeffs"]));
  }
  if (inspect.lamp_selector && inspect.lamp_selector.last) {
    expectEqual(`${label} last /hal/lamp_selector`,
                pick(last["/hal/lamp_selector"], ["seq", "lamp", "state", "levels"]),
                pick(inspect.lamp_selector.last, ["seq", "lamp", "state", "levels"]));
  }
  if (inspect.last_frame) {
    expectEqual(`${label} last /replica/frame`, pick(last["/replica/frame"], ["frame", "tick_ns"]),
                inspect.last_frame);
  }
  expectEqual(`${label} session software`, last["/replica/session"].software, inspect.software);
}

async function indexed() {
  const readable = {
    size: async () => BigInt(bytes.length),
    read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  const messages = [];
  for await (const m of reader.readMessages({ validateCrcs: true })) {
    messages.push(m);
  }
  const t = tally(messages, reader.channelsById);
  compare("indexed", t);
  // The summary's statistics agree with what was read.
  const stats = reader.statistics;
  expectEqual("statistics message_count", Number(stats.messageCount), messages.length);
  for (const [id, n] of stats.channelMessageCounts) {
    const topic = reader.channelsById.get(id).topic;
    expectEqual(`statistics count on ${topic}`, Number(n), t.counts[topic] || 0);
  }
  expectEqual("statistics chunk_count", stats.chunkCount, inspect.chunks);
  for (const [, schema] of reader.schemasById) {
    expectEqual(`schema ${schema.name} encoding`, schema.encoding, "jsonschema");
    JSON.parse(new TextDecoder().decode(schema.data)); // a JSON Schema must be JSON
  }
  return messages.length;
}

function streamed() {
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(bytes);
  const channelsById = new Map();
  const messages = [];
  for (let r; (r = reader.nextRecord()); ) {
    if (r.type === "Channel") {
      channelsById.set(r.id, r);
    } else if (r.type === "Message") {
      messages.push(r);
    }
  }
  if (!reader.done()) {
    console.error(`FAIL ${file}: the streaming reader did not reach a valid footer`);
    failures++;
  }
  compare("streamed", tally(messages, channelsById));
  return messages.length;
}

(async () => {
  try {
    // Format 1 recordings have no summary: only a linear read applies to them.
    const n = inspect.indexed ? await indexed() : streamed();
    if (inspect.indexed) {
      streamed();
    }
    if (failures === 0) {
      console.log(`ok ${file}: ${n} messages on ${Object.keys(inspect.channels).length} channels `
                  + `agree with replica inspect`);
    }
  } catch (e) {
    console.error(`FAIL ${file}: @mcap/core could not read it: ${e.message}`);
    failures++;
  }
  process.exit(failures === 0 ? 0 : 1);
})();
