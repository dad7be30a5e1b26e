#!/usr/bin/env node
// Test tool: a simulated `selfcal detect` folder (selfcal_render_sequence --detect-folder: PNG images and a
// selfcal-poses list of joint angles) as a ROS 2 recording, written by an MCAP writer that is not selfcal's
// reader: npm's @mcap/core (the MCAP writer of the format's authors) and @foxglove/cdr (the CDR
// serializer), zstd chunks through Debian's `zstd` program. The recording, as rosbag2 would store it:
//   /joint_states  sensor_msgs/msg/JointState at 100 Hz: the arm still at each pose for 1 s, then 1 s of
//                  motion (smoothstep) to the next pose;
//   IMAGE_TOPIC    each pose's image 0.5 s into its still second, and an image half-way through every motion
//                  (which a reader must leave out): sensor_msgs/msg/Image mono8 (the PNG decoded here) or,
//                  with --compressed, sensor_msgs/msg/CompressedImage holding the PNG file as it is.
// usage: node write_bag.js FOLDER OUT.mcap [--compressed] [--compression zstd|none] [--joint-names a,b,..]
//                          [--extra-joint NAME] [--image-topic TOPIC]
"use strict";
const fs = require("fs");
const path = require("path");
const zlib = require("zlib");
const { execFileSync } = require("child_process");
const { McapWriter } = require("@mcap/core");
const { CdrWriter } = require("@foxglove/cdr");

function usage(message) {
  process.stderr.write(`write_bag.js: ${message}\n`);
  process.exit(2);
}

const args = process.argv.slice(2);
const positional = [];
const opts = { compressed: false, compression: "zstd", jointNames: null, extraJoint: null, imageTopic: null };
for (let i = 0; i < args.length; ++i) {
  if (args[i] === "--compressed") opts.compressed = true;
  else if (args[i] === "--compression") opts.compression = args[++i];
  else if (args[i] === "--joint-names") opts.jointNames = args[++i].split(",");
  else if (args[i] === "--extra-joint") opts.extraJoint = args[++i];
  else if (args[i] === "--image-topic") opts.imageTopic = args[++i];
  else positional.push(args[i]);
}
if (positional.length !== 2) usage("FOLDER OUT.mcap expected");
const [folder, out] = positional;
const imageTopic = opts.imageTopic ?? (opts.compressed ? "/camera/image_raw/compressed" : "/camera/image_raw");

// The poses list: `  - {image: NAME, joints_rad: [a, b, ...](, role: verification)}` lines.
const poses = [];
for (const line of fs.readFileSync(path.join(folder, "poses.yaml"), "utf8").split("\n")) {
  const m = line.match(/^\s*-\s*\{image:\s*"?([^",]+)"?,\s*joints_rad:\s*\[([^\]]*)\]/);
  if (m) poses.push({ image: m[1], joints: m[2].split(",").map(Number) });
}
if (poses.length === 0) usage(`no pose in ${folder}/poses.yaml`);
const dof = poses[0].joints.length;
const names = opts.jointNames ?? Array.from({ length: dof }, (_, j) => `joint_${j + 1}`);

// An 8-bit grey, non-interlaced PNG's pixels (what the renderer writes): IDAT inflated, rows unfiltered.
function decodeGreyPng(bytes, file) {
  let pos = 8, width = 0, height = 0;
  const idat = [];
  while (pos < bytes.length) {
    const length = bytes.readUInt32BE(pos), type = bytes.toString("ascii", pos + 4, pos + 8);
    const data = bytes.subarray(pos + 8, pos + 8 + length);
    if (type === "IHDR") {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      if (data[8] !== 8 || data[9] !== 0 || data[12] !== 0) usage(`${file}: not an 8-bit grey non-interlaced PNG`);
    } else if (type === "IDAT") idat.push(data);
    pos += 12 + length;
  }
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const pixels = Buffer.alloc(width * height);
  for (let r = 0; r < height; ++r) {
    const filter = raw[r * (width + 1)], row = raw.subarray(r * (width + 1) + 1, (r + 1) * (width + 1));
    for (let c = 0; c < width; ++c) {
      const a = c > 0 ? pixels[r * width + c - 1] : 0, b = r > 0 ? pixels[(r - 1) * width + c] : 0;
      const d = c > 0 && r > 0 ? pixels[(r - 1) * width + c - 1] : 0;
      let p = 0;
      if (filter === 1) p = a;
      else if (filter === 2) p = b;
      else if (filter === 3) p = (a + b) >> 1;
      else if (filter === 4) {
        const e = a + b - d, pa = Math.abs(e - a), pb = Math.abs(e - b), pc = Math.abs(e - d);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? b : d;
      }
      pixels[r * width + c] = (row[c] + p) & 0xff;
    }
  }
  return { width, height, pixels };
}

function header(w, ns) {
  w.int32(Number(ns / 1000000000n));
  w.uint32(Number(ns % 1000000000n));
}

function jointState(ns, q) {
  const w = new CdrWriter();
  header(w, ns);
  w.string("");
  const all = opts.extraJoint ? [...names, opts.extraJoint] : names;
  const values = opts.extraJoint ? [...q, 0.04] : q;
  // A named robot's joints in another order than its own: the reader must pick them by name.
  const order = opts.jointNames ? all.map((_, k) => all.length - 1 - k) : all.map((_, k) => k);
  w.sequenceLength(all.length);
  for (const k of order) w.string(all[k]);
  w.float64Array(order.map((k) => values[k]), true);
  w.float64Array([], true);
  w.float64Array([], true);
  return w.data;
}

function image(ns, file) {
  const bytes = fs.readFileSync(path.join(folder, file));
  const w = new CdrWriter();
  header(w, ns);
  w.string("camera_optical_frame");
  if (opts.compressed) {
    w.string("png");
    w.uint8Array(bytes, true);
  } else {
    const png = decodeGreyPng(bytes, file);
    w.uint32(png.height);
    w.uint32(png.width);
    w.string("mono8");
    w.uint8(0);
    w.uint32(png.width);
    w.uint8Array(png.pixels, true);
  }
  return w.data;
}

function compressChunk(data) {
  if (opts.compression === "none") return { compression: "", compressedData: data };
  return { compression: "zstd", compressedData: new Uint8Array(execFileSync("zstd", ["-q", "-c", "-3"], { input: data, maxBuffer: 1 << 30 })) };
}

async function main() {
  const fd = fs.openSync(out, "w");
  let position = 0n;
  const writable = {
    write: async (buffer) => {
      fs.writeSync(fd, buffer);
      position += BigInt(buffer.byteLength);
    },
    position: () => position,
  };
  const writer = new McapWriter({ writable, useChunks: true, chunkSize: 4 << 20, compressChunk });
  await writer.start({ profile: "ros2", library: "selfcal test/tools/mcap_writer (@mcap/core)" });
  const text = new TextEncoder();
  const jointSchema = await writer.registerSchema({ name: "sensor_msgs/msg/JointState", encoding: "ros2msg",
    data: text.encode("std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n") });
  const imageSchema = await writer.registerSchema(opts.compressed
    ? { name: "sensor_msgs/msg/CompressedImage", encoding: "ros2msg", data: text.encode("std_msgs/Header header\nstring format\nuint8[] data\n") }
    : { name: "sensor_msgs/msg/Image", encoding: "ros2msg",
        data: text.encode("std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data\n") });
  const jointChannel = await writer.registerChannel({ topic: "/joint_states", schemaId: jointSchema, messageEncoding: "cdr", metadata: new Map() });
  const imageChannel = await writer.registerChannel({ topic: imageTopic, schemaId: imageSchema, messageEncoding: "cdr", metadata: new Map() });
  const start = 1700000000n * 1000000000n, tick = 10000000n;  // 100 Hz
  let sequence = 0;
  const add = async (channelId, ns, data) =>
    writer.addMessage({ channelId, sequence: sequence++, logTime: ns + 1000000n, publishTime: ns, data });
  // Per pose: 100 ticks still (image at tick 50), then 100 ticks of motion to the next (image at tick 150).
  for (let p = 0; p < poses.length; ++p) {
    const from = poses[p].joints, to = poses[Math.min(p + 1, poses.length - 1)].joints;
    const ticks = p + 1 < poses.length ? 200 : 100;
    for (let k = 0; k < ticks; ++k) {
      const ns = start + BigInt(p * 200 + k) * tick;
      const s = k < 100 ? 0 : (k - 100) / 100, smooth = s * s * (3 - 2 * s);
      await add(jointChannel, ns, jointState(ns, from.map((q, j) => (k < 100 ? q : q + smooth * (to[j] - q)))));
      if (k === 50) await add(imageChannel, ns + 3000000n, image(ns + 3000000n, poses[p].image));
      if (k === 150) await add(imageChannel, ns + 3000000n, image(ns + 3000000n, poses[p].image));
    }
  }
  await writer.end();
  fs.closeSync(fd);
}

main().catch((error) => {
  process.stderr.write(`write_bag.js: ${error.stack ?? error}\n`);
  process.exit(1);
});
