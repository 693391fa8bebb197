// Independent check of format 4's channels of what was shown, with @mcap/core and Node's own zlib
// (no image library): the last /replica/thumbnail (foxglove.CompressedImage, PNG in base64) is
// decoded here and compared, byte for byte, with 'replica run --snapshot's PNG of the same frame
// downscaled here by the rule platform/image/thumbnail.h states (box mean over
// [floor(x W / w), floor((x + 1) W / w)), rounded half up). Also: the Foxglove schema names and
// encodings, one display digest per frame, transforms naming the booth's frames.
// Usage: node thumbnail_check.cjs RECORDING SNAPSHOT_PNG FRAMES
"use strict";
const fs = require("fs");
const zlib = require("zlib");
const { McapIndexedReader } = require("@mcap/core");
const fzstd = require("fzstd");

const [file, snapshotPath, framesArg] = process.argv.slice(2);
if (!file || !snapshotPath || !framesArg) {
  console.error("usage: node thumbnail_check.cjs RECORDING SNAPSHOT_PNG FRAMES");
  process.exit(2);
}
let failures = 0;
function fail(msg) {
  console.error(`FAIL ${file}: ${msg}`);
  failures++;
}

// A PNG decoder for 8-bit, non-interlaced greyscale/RGB/RGBA: chunks, inflate, unfilter.
function decodePng(buf) {
  const sig = [0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a];
  sig.forEach((b, i) => {
    if (buf[i] !== b) throw new Error("not a PNG (signature)");
  });
  let pos = 8;
  let width = 0, height = 0, colourType = -1;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos);
    const type = buf.toString("latin1", pos + 4, pos + 8);
    const data = buf.subarray(pos + 8, pos + 8 + len);
    if (type === "IHDR") {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      if (data[8] !== 8 || data[12] !== 0) throw new Error("only 8-bit non-interlaced PNGs");
      colourType = data[9];
    } else if (type === "IDAT") {
      idat.push(data);
    } else if (type === "IEND") {
      break;
    }
    pos += 12 + len;
  }
  const channels = { 0: 1, 2: 3, 6: 4 }[colourType];
  if (!channels) throw new Error(`PNG colour type ${colourType} not handled`);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const out = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const f = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; x++) {
      const a = x >= channels ? out[y * stride + x - channels] : 0;
      const b = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= channels && y > 0 ? out[(y - 1) * stride + x - channels] : 0;
      let p;
      switch (f) {
        case 0: p = 0; break;
        case 1: p = a; break;
        case 2: p = b; break;
        case 3: p = (a + b) >> 1; break;
        case 4: {
          const pa = Math.abs(b - c), pb = Math.abs(a - c), pc = Math.abs(a + b - 2 * c);
          p = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default: throw new Error(`PNG filter ${f}`);
      }
      out[y * stride + x] = (line[x] + p) & 0xff;
    }
  }
  return { width, height, channels, pixels: out };
}

// The thumbnail rule, restated: RGB out of an RGBA picture (rows top-down).
function downscale(img, toWidth) {
  const W = img.width, H = img.height;
  const w = Math.min(toWidth, W);
  const h = Math.min(Math.max(Math.floor((H * w * 2 + W) / (2 * W)), 1), H);
  const out = Buffer.alloc(w * h * 3);
  for (let y = 0; y < h; y++) {
    const y0 = Math.floor((y * H) / h), y1 = Math.max(Math.floor(((y + 1) * H) / h), y0 + 1);
    for (let x = 0; x < w; x++) {
      const x0 = Math.floor((x * W) / w), x1 = Math.max(Math.floor(((x + 1) * W) / w), x0 + 1);
      const sum = [0, 0, 0];
      for (let sy = y0; sy < y1; sy++) {
        for (let sx = x0; sx < x1; sx++) {
          for (let c = 0; c < 3; c++) sum[c] += img.pixels[(sy * W + sx) * img.channels + c];
        }
      }
      const n = (y1 - y0) * (x1 - x0);
      for (let c = 0; c < 3; c++) out[(y * w + x) * 3 + c] = Math.floor((sum[c] + Math.floor(n / 2)) / n);
    }
  }
  return { width: w, height: h, pixels: out };
}

(async () => {
  try {
    const bytes = new Uint8Array(fs.readFileSync(file));
    const readable = {
      size: async () => BigInt(bytes.length),
      read: async (offset, size) => bytes.subarray(Number(offset), Number(offset + size)),
    };
    const reader = await McapIndexedReader.Initialize({
      readable,
      decompressHandlers: { zstd: (b) => fzstd.decompress(b) },
    });
    const want = {
      "/replica/thumbnail": "foxglove.CompressedImage",
      "/tf": "foxglove.FrameTransforms",
      "/replica/eye": "foxglove.PoseInFrame",
      "/replica/log": "foxglove.Log",
      "/replica/light": "replica.Light",
      "/replica/display_digest": "replica.DisplayDigest",
    };
    const topicOf = new Map();
    for (const [id, ch] of reader.channelsById) {
      topicOf.set(id, ch.topic);
      if (ch.topic in want) {
        const schema = reader.schemasById.get(ch.schemaId);
        if (!schema || schema.name !== want[ch.topic] || schema.encoding !== "jsonschema" ||
            ch.messageEncoding !== "json") {
          fail(`${ch.topic}: schema ${schema && schema.name} (${schema && schema.encoding}), want ${want[ch.topic]} (jsonschema, json)`);
        }
      }
    }
    const byTopic = {};
    for await (const m of reader.readMessages({ validateCrcs: true })) {
      const t = topicOf.get(m.channelId);
      (byTopic[t] = byTopic[t] || []).push(JSON.parse(new TextDecoder().decode(m.data)));
    }
    const digests = byTopic["/replica/display_digest"] || [];
    if (digests.length !== Number(framesArg)) fail(`${digests.length} display digests for ${framesArg} frames`);
    if (digests.some((d) => !/^[0-9a-f]{16}$/.test(d.rgba) || d.hash !== "xxh3_64")) fail("malformed display digest");
    const tf = (byTopic["/tf"] || [])[0];
    const children = tf ? tf.transforms.map((t) => `${t.parent_frame_id}>${t.child_frame_id}`).sort().join(",") : "";
    if (children !== "booth>eye,booth>panel,booth>tracker") fail(`/tf frames: '${children}'`);
    const light = (byTopic["/replica/light"] || [])[0];
    if (!light || !["lamp", "direct-sensor"].includes(light.mode) || !light.why) fail("no decided light");
    const thumbs = byTopic["/replica/thumbnail"] || [];
    if (thumbs.length === 0) throw new Error("no /replica/thumbnail message");
    const last = thumbs[thumbs.length - 1];
    if (last.format !== "png" || !(last.timestamp.sec > 0)) fail(`thumbnail format ${last.format}, timestamp ${JSON.stringify(last.timestamp)}`);
    const thumb = decodePng(Buffer.from(last.data, "base64"));
    const snap = decodePng(fs.readFileSync(snapshotPath));
    const mine = downscale(snap, thumb.width);
    if (thumb.channels !== 3 || mine.width !== thumb.width || mine.height !== thumb.height) {
      fail(`thumbnail ${thumb.width}x${thumb.height}x${thumb.channels}, snapshot downscaled ${mine.width}x${mine.height}x3`);
    } else {
      let differ = 0, maxd = 0;
      for (let i = 0; i < mine.pixels.length; i++) {
        const d = Math.abs(mine.pixels[i] - thumb.pixels[i]);
        differ += d > 0 ? 1 : 0;
        maxd = Math.max(maxd, d);
      }
      if (differ > 0) fail(`thumbnail differs from the downscaled snapshot in ${differ} of ${mine.pixels.length} values (max ${maxd})`);
      // A uniform picture would make the comparison vacuous.
      const distinct = new Set();
      for (let i = 0; i < mine.pixels.length; i += 3) distinct.add(mine.pixels.readUIntBE(i, 3));
      if (distinct.size < 8) fail(`only ${distinct.size} distinct colours in the thumbnail`);
      if (failures === 0) {
        console.log(`ok ${file}: last of ${thumbs.length} thumbnails (${thumb.width}x${thumb.height}, ${distinct.size} colours) equals the snapshot downscaled independently; ${digests.length} display digests; /tf, /replica/eye, /replica/light, /replica/log on foxglove schemas`);
      }
    }
  } catch (e) {
    fail(`${e.message}`);
  }
  process.exit(failures === 0 ? 0 : 1);
})();
