// A CoNUS file read in the browser: the OpenEXR multipart container (headers, offset tables,
// scanline and one-level tiled chunks; NONE, RLE, ZIPS and ZIP compression, ZIP through the
// browser's own DecompressionStream; HALF and FLOAT pixels), then the CoNUS part and the sampling
// map as spec/conus-format.md states them (V2..V10 checked before use; V11 on the grid).
// Every failure is one Error whose message is one line, said on the page.
"use strict";

const ConusExr = (() => {
  const kCompressionNames = ["none", "rle", "zips", "zip", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab", "htj2k256", "htj2k32"];
  // Scanlines per chunk for the compressions read here.
  const kLinesPerChunk = { 0: 1, 1: 1, 2: 1, 3: 16 };
  const kMaxSide = 65536;
  const kMaxMapSide = 4097;
  // A map no finer than 4 nodes a pixel of the image's longer side, plus one, and 129 nodes a side
  // whatever the image (core/map_rules.h's maxSideForImage; limits mapNodesPerPixel, mapSideAlways).
  const kMapNodesPerPixel = 4, kMapSideAlways = 129;
  const maxMapSideForImage = (width, height) => Math.max(kMapSideAlways, kMapNodesPerPixel * Math.max(width, height) + 1);
  const kMaxAttributeBytes = 1 << 20;

  class Reader {
    constructor(bytes) {
      this.bytes = bytes;
      this.view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      this.at = 0;
    }
    need(n, what) {
      if (n < 0 || this.at + n > this.bytes.length) throw new Error(`damaged file: ${what} runs past the end of the file`);
    }
    u8() { this.need(1, "a header"); return this.bytes[this.at++]; }
    i32() { this.need(4, "a header"); const v = this.view.getInt32(this.at, true); this.at += 4; return v; }
    u32() { this.need(4, "a header"); const v = this.view.getUint32(this.at, true); this.at += 4; return v; }
    f32() { this.need(4, "a header"); const v = this.view.getFloat32(this.at, true); this.at += 4; return v; }
    f64() { this.need(8, "a header"); const v = this.view.getFloat64(this.at, true); this.at += 8; return v; }
    u64() {
      this.need(8, "an offset table");
      const lo = this.view.getUint32(this.at, true), hi = this.view.getUint32(this.at + 4, true);
      this.at += 8;
      return hi * 4294967296 + lo;
    }
    // A NUL-terminated name of at most 255 bytes (OpenEXR's long names).
    name() {
      const start = this.at;
      while (this.at < this.bytes.length && this.bytes[this.at] !== 0) {
        if (this.at - start > 255) throw new Error("damaged file: a header name longer than 255 bytes");
        ++this.at;
      }
      if (this.at >= this.bytes.length) throw new Error("damaged file: a header runs past the end of the file");
      // Control characters as "?": a name goes into one line of error.
      const text = new TextDecoder().decode(this.bytes.subarray(start, this.at)).replace(/[\u0000-\u001f\u007f]/g, "?");
      ++this.at;
      return text;
    }
  }

  // One attribute's value from `size` bytes of `type`; types this reader has no use for are kept as bytes.
  function attributeValue(r, type, size) {
    const end = r.at + size;
    let value;
    switch (type) {
      case "int": value = r.i32(); break;
      case "float": value = r.f32(); break;
      case "double": value = r.f64(); break;
      case "string": value = new TextDecoder().decode(r.bytes.subarray(r.at, end)); break;
      case "v2i": value = [r.i32(), r.i32()]; break;
      case "v2f": value = [r.f32(), r.f32()]; break;
      case "box2i": value = { xMin: r.i32(), yMin: r.i32(), xMax: r.i32(), yMax: r.i32() }; break;
      case "compression": case "lineOrder": value = r.u8(); break;
      case "floatvector": {
        if (size % 4) throw new Error("damaged file: a floatvector of " + size + " bytes");
        value = [];
        for (let i = 0; i < size / 4; ++i) value.push(r.f32());
        break;
      }
      case "tiledesc": value = { xSize: r.u32(), ySize: r.u32(), mode: r.u8() }; break;
      case "chlist": {
        value = [];
        while (r.at < end && r.bytes[r.at] !== 0) {
          const name = r.name();
          const pixelType = r.i32();
          r.at += 4;  // pLinear and reserved
          const xSampling = r.i32(), ySampling = r.i32();
          value.push({ name, pixelType, xSampling, ySampling });
        }
        r.at += 1;
        break;
      }
      default: value = r.bytes.subarray(r.at, end);
    }
    if (r.at > end) throw new Error(`damaged file: attribute of type ${type} is longer than its declared ${size} bytes`);
    r.at = end;
    return value;
  }

  function readHeader(r) {
    const header = {};
    for (;;) {
      r.need(1, "a header");
      if (r.bytes[r.at] === 0) { ++r.at; return header; }
      const name = r.name(), type = r.name(), size = r.i32();
      if (size < 0 || size > kMaxAttributeBytes) throw new Error(`damaged file: attribute ${name} declares ${size} bytes`);
      r.need(size, `attribute ${name}`);
      header[name] = { type, value: attributeValue(r, type, size) };
    }
  }

  function value(header, name, type) {
    const a = header[name];
    if (!a) return undefined;
    if (type && a.type !== type) throw new Error(`not a valid CoNUS file: ${name} is a ${a.type}, not a ${type}`);
    return a.value;
  }

  // The headers and offset tables of an OpenEXR file: [{header, offsets, type, name}].
  function readParts(bytes) {
    const r = new Reader(bytes);
    if (bytes.length < 8 || r.u32() !== 20000630) throw new Error("not an OpenEXR file (no OpenEXR magic number), so not a CoNUS file");
    const version = r.u32();
    if ((version & 0xff) !== 2) throw new Error(`not a readable OpenEXR file: version ${version & 0xff}`);
    const tiled = (version & 0x200) !== 0, deep = (version & 0x800) !== 0, multi = (version & 0x1000) !== 0;
    if (deep) throw new Error("not a CoNUS file: deep OpenEXR data");
    const headers = [];
    if (multi) {
      for (;;) {
        r.need(1, "the headers");
        if (r.bytes[r.at] === 0) { ++r.at; break; }
        headers.push(readHeader(r));
        if (headers.length > 1024) throw new Error("damaged file: more than 1024 parts");
      }
    } else {
      headers.push(readHeader(r));
    }
    const parts = [];
    for (const header of headers) {
      const type = value(header, "type", "string") || (tiled ? "tiledimage" : "scanlineimage");
      const window = value(header, "dataWindow", "box2i");
      if (!window) throw new Error("damaged file: a part has no dataWindow");
      const width = window.xMax - window.xMin + 1, height = window.yMax - window.yMin + 1;
      if (!(width >= 1 && height >= 1 && width <= kMaxSide && height <= kMaxSide))
        throw new Error(`damaged file: a part's dataWindow is ${width}x${height}`);
      let chunks = value(header, "chunkCount", "int");
      const compression = value(header, "compression", "compression") ?? 0;
      const tiles = value(header, "tiles", "tiledesc");
      if (chunks === undefined) {
        if (type === "tiledimage") {
          if (!tiles) throw new Error("damaged file: a tiled part has no tile description");
          chunks = Math.ceil(width / tiles.xSize) * Math.ceil(height / tiles.ySize);
        } else {
          chunks = Math.ceil(height / (kLinesPerChunk[compression] || 32));
        }
      }
      if (!(chunks >= 1 && chunks <= bytes.length / 8)) throw new Error(`damaged file: ${chunks} chunks in a file of ${bytes.length} bytes`);
      parts.push({ header, type, name: value(header, "name", "string") || "", window, width, height, compression, tiles, chunks, multi });
    }
    for (const part of parts) {
      part.offsets = new Array(part.chunks);
      for (let i = 0; i < part.chunks; ++i) {
        const o = r.u64();
        if (!(o >= r.at || o === 0) || o >= bytes.length) throw new Error("damaged file: a chunk offset lies outside the file");
        part.offsets[i] = o;
      }
    }
    return parts;
  }

  const kHalfToFloat = (() => {
    const t = new Float32Array(65536);
    for (let h = 0; h < 65536; ++h) {
      const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 0x1f, m = h & 0x3ff;
      t[h] = e === 0 ? s * m * 2 ** -24 : e === 31 ? (m ? NaN : s * Infinity) : s * (1 + m / 1024) * 2 ** (e - 15);
    }
    return t;
  })();

  async function inflate(data, expected) {
    const stream = new Blob([data]).stream().pipeThrough(new DecompressionStream("deflate"));
    const reader = stream.getReader();
    const out = new Uint8Array(expected);
    let at = 0;
    for (;;) {
      let next;
      try {
        next = await reader.read();
      } catch (e) {
        throw new Error(`damaged file: a zip chunk does not inflate (${e.message})`);
      }
      const { done, value: piece } = next;
      if (done) break;
      if (at + piece.length > expected) { reader.cancel(); throw new Error("damaged file: a zip chunk holds more than its lines"); }
      out.set(piece, at);
      at += piece.length;
    }
    if (at !== expected) throw new Error("damaged file: a zip chunk holds fewer bytes than its lines");
    return out;
  }

  function unRle(data, expected) {
    const out = new Uint8Array(expected);
    let i = 0, o = 0;
    while (i < data.length) {
      const count = (data[i] << 24) >> 24;
      ++i;
      if (count < 0) {
        const n = -count;
        if (i + n > data.length || o + n > expected) throw new Error("damaged file: an rle run runs past its chunk");
        out.set(data.subarray(i, i + n), o);
        i += n; o += n;
      } else {
        const n = count + 1;
        if (i >= data.length || o + n > expected) throw new Error("damaged file: an rle run runs past its chunk");
        out.fill(data[i], o, o + n);
        ++i; o += n;
      }
    }
    if (o !== expected) throw new Error("damaged file: an rle chunk holds fewer bytes than its lines");
    return out;
  }

  // OpenEXR's zip and rle filters: the byte-wise difference predictor over the whole chunk (undone
  // here in place), and the chunk's bytes split in two, its even bytes first ((n+1)/2 of them), then
  // its odd ones (split: true). A chunk of HALF samples is read from the split bytes as they are
  // (sample k: byte k low, byte (n+1)/2 + k high); interleave() puts them back in order for FLOAT.
  function undoPredictor(t) {
    const n = t.length;
    for (let i = 1, previous = t[0]; i < n; ++i) t[i] = previous = (previous + t[i] - 128) & 255;
    return { bytes: t, split: true };
  }
  function interleave(t) {
    const n = t.length, out = new Uint8Array(n), half = (n + 1) >> 1;
    for (let i = 0; i < half; ++i) out[2 * i] = t[i];
    for (let i = half, o = 1; i < n; ++i, o += 2) out[o] = t[i];
    return out;
  }

  // A chunk's bytes, unpacked: {bytes, split} (see undoPredictor).
  async function unpack(part, packed, expected) {
    if (packed.length === expected) return { bytes: packed, split: false };  // stored raw where compression would not shrink it
    switch (part.compression) {
      case 0: throw new Error(`damaged file: an uncompressed chunk of ${packed.length} bytes for ${expected}`);
      case 1: return undoPredictor(unRle(packed, expected));
      case 2: case 3: return undoPredictor(await inflate(packed, expected));
      default:
        throw new Error(`compression ${kCompressionNames[part.compression] || part.compression} is not read by this page ` +
          "(conus web and conus serve write zip)");
    }
  }

  // The part's pixels as planes, one per channel (in the part's channel order): a HALF channel's as
  // its 16-bit values (Uint16Array: what a half-float texture takes as it is), a FLOAT one's as a
  // Float32Array; halfToFloat() converts.
  async function readPixels(bytes, part, partIndex) {
    const channels = value(part.header, "channels", "chlist");
    if (!channels || !channels.length) throw new Error(`damaged file: part ${part.name} has no channels`);
    for (const c of channels) {
      if (c.pixelType !== 1 && c.pixelType !== 2) throw new Error(`not a valid CoNUS file: channel ${c.name} of part ${part.name} is not HALF or FLOAT (V3)`);
      if (c.xSampling !== 1 || c.ySampling !== 1) throw new Error(`not a valid CoNUS file: channel ${c.name} is subsampled (V3)`);
    }
    if (!(part.compression in kLinesPerChunk)) await unpack(part, new Uint8Array(0), 1);  // names the compression
    const { width, height, window } = part;
    const planes = channels.map((c) => (c.pixelType === 1 ? new Uint16Array(width * height) : new Float32Array(width * height)));
    const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const tiled = part.type === "tiledimage";
    if (tiled && (!part.tiles || (part.tiles.mode & 0xf) !== 0 || part.tiles.xSize < 1 || part.tiles.ySize < 1 ||
                  part.tiles.xSize * part.tiles.ySize > (1 << 24)))
      throw new Error("not read by this page: a tiled part that is not one level of tiles of at most 2^24 pixels");
    const seen = new Uint8Array(part.chunks);
    const allHalf = channels.every((c) => c.pixelType === 1);
    const chunk = async (offset, index) => {
      if (offset === 0) throw new Error(`damaged file: chunk ${index} of part ${part.name} is missing`);
      let at = offset;
      const int = () => {
        if (at + 4 > bytes.length) throw new Error("damaged file: a chunk runs past the end of the file");
        const v = view.getInt32(at, true);
        at += 4;
        return v;
      };
      if (part.multi && int() !== partIndex) throw new Error(`damaged file: chunk ${index} of part ${part.name} names another part`);
      let x0 = 0, y0, w = width, h;
      if (tiled) {
        const tx = int(), ty = int(), lx = int(), ly = int();
        const nx = Math.ceil(width / part.tiles.xSize), ny = Math.ceil(height / part.tiles.ySize);
        if (lx !== 0 || ly !== 0 || tx < 0 || ty < 0 || tx >= nx || ty >= ny) throw new Error("damaged file: a tile outside the image");
        x0 = tx * part.tiles.xSize;
        y0 = ty * part.tiles.ySize;
        w = Math.min(part.tiles.xSize, width - x0);
        h = Math.min(part.tiles.ySize, height - y0);
        index = ty * nx + tx;
      } else {
        y0 = int() - window.yMin;
        const lines = kLinesPerChunk[part.compression];
        if (y0 < 0 || y0 >= height || y0 % lines) throw new Error(`damaged file: a chunk starts at line ${y0 + window.yMin}`);
        index = y0 / lines;
        h = Math.min(lines, height - y0);
      }
      if (seen[index]) throw new Error("damaged file: two chunks hold the same lines");
      seen[index] = 1;
      const size = int();
      const expected = h * channels.reduce((sum, c) => sum + w * (c.pixelType === 1 ? 2 : 4), 0);
      if (size < 0 || at + size > bytes.length) throw new Error("damaged file: a chunk runs past the end of the file");
      if (size > expected * 2048 + 1024) throw new Error("damaged file: a chunk larger than its lines could compress to");
      const unpacked = await unpack(part, bytes.subarray(at, at + size), expected);
      if (unpacked.split && allHalf) {
        const t = unpacked.bytes, high = (t.length + 1) >> 1;
        let k = 0;
        for (let y = 0; y < h; ++y) {
          const row = (y0 + y) * width + x0;
          for (let ci = 0; ci < channels.length; ++ci) {
            const plane = planes[ci];
            for (let x = 0; x < w; ++x, ++k) plane[row + x] = t[k] | (t[high + k] << 8);
          }
        }
        return;
      }
      const raw = unpacked.split ? interleave(unpacked.bytes) : unpacked.bytes;
      // Samples through typed views where aligned (every browser is little-endian, as EXR is), else a DataView.
      const rv = new DataView(raw.buffer, raw.byteOffset, raw.byteLength);
      let p = 0;
      for (let y = 0; y < h; ++y) {
        const row = (y0 + y) * width + x0;
        for (let ci = 0; ci < channels.length; ++ci) {
          const plane = planes[ci], at = raw.byteOffset + p;
          if (channels[ci].pixelType === 1) {
            if (at % 2 === 0) plane.set(new Uint16Array(raw.buffer, at, w), row);
            else for (let x = 0; x < w; ++x) plane[row + x] = rv.getUint16(p + 2 * x, true);
            p += 2 * w;
          } else {
            if (at % 4 === 0) plane.set(new Float32Array(raw.buffer, at, w), row);
            else for (let x = 0; x < w; ++x) plane[row + x] = rv.getFloat32(p + 4 * x, true);
            p += 4 * w;
          }
        }
      }
    };
    // Two chunks in flight: the inflate of one while the other is placed (more, on a busy core,
    // only queue up; measured in bench/notes/2026-12-07-web-speed.md).
    let next = 0;
    const worker = async () => {
      while (next < part.chunks) {
        const index = next++;
        await chunk(part.offsets[index], index);
      }
    };
    await Promise.all([worker(), worker()]);
    return { channels: channels.map((c) => c.name), pixelTypes: channels.map((c) => c.pixelType), planes, width, height };
  }

  // The grid rules the page relies on: V8..V11 of spec/conus-format.md.
  function checkGrid(nodes, n, m) {
    for (let k = 0; k < n * m * 2; ++k) {
      if (!Number.isFinite(nodes[k])) throw new Error("not a valid CoNUS file: a sampling-map node is not finite (V8)");
      if (nodes[k] < 0 || nodes[k] > 1) throw new Error("not a valid CoNUS file: a sampling-map node lies outside [0,1] (V9)");
    }
    const u = (i, j) => nodes[2 * (j * n + i)], v = (i, j) => nodes[2 * (j * n + i) + 1];
    for (let j = 0; j < m; ++j)
      if (u(0, j) !== 0 || u(n - 1, j) !== 1) throw new Error(`not a valid CoNUS file: a boundary node of row ${j} is off its edge (V10)`);
    for (let i = 0; i < n; ++i)
      if (v(i, 0) !== 0 || v(i, m - 1) !== 1) throw new Error(`not a valid CoNUS file: a boundary node of column ${i} is off its edge (V10)`);
    // V11: at each corner of each cell, taken in the order (i,j), (i+1,j), (i+1,j+1), (i,j+1), the
    // cross product of the incident edges is positive (v down, as the identity's).
    const cu = new Float64Array(4), cv = new Float64Array(4);
    for (let j = 0; j + 1 < m; ++j)
      for (let i = 0; i + 1 < n; ++i) {
        const a = 2 * (j * n + i), b = a + 2 * n;
        cu[0] = nodes[a]; cv[0] = nodes[a + 1]; cu[1] = nodes[a + 2]; cv[1] = nodes[a + 3];
        cu[2] = nodes[b + 2]; cv[2] = nodes[b + 3]; cu[3] = nodes[b]; cv[3] = nodes[b + 1];
        for (let c = 0; c < 4; ++c) {
          const p = (c + 3) & 3, q = (c + 1) & 3;
          const cross = (cu[c] - cu[p]) * (cv[q] - cv[c]) - (cv[c] - cv[p]) * (cu[q] - cu[c]);
          if (!(cross > 1e-12)) throw new Error(`not a valid CoNUS file: map cell (${i}, ${j}) is folded or degenerate (V11)`);
        }
      }
  }

  // A CoNUS file from its bytes: {image: {width, height, channels, planes, half}, map: {columns, rows,
  // nodes (Float32Array u,v per node)}, sourceSize: [w, h], foci: [[u,v,r,k]...], mapKind}.
  async function readConus(bytes, limits = {}) {
    const maxSide = limits.maxSide || 16384, maxValues = limits.maxValues || 2 ** 27;
    const parts = readParts(bytes);
    const conusIndex = parts.findIndex((p) => p.name === "conus");
    if (conusIndex < 0) {
      if (parts.some((p) => p.name === "conus.px")) throw new Error("a CoNUS reflection asset (six faces): this page shows single images");
      throw new Error("not a CoNUS file: an OpenEXR file with no part named conus (V2)");
    }
    const conus = parts[conusIndex], h = conus.header;
    const version = value(h, "conus:version", "int");
    if (version === undefined) throw new Error("not a CoNUS file: part conus has no conus:version (V2)");
    if (version > 1) throw new Error(`written by a newer CoNUS (version ${version})`);
    if (version !== 1) throw new Error(`not a valid CoNUS file: conus:version ${version} (V2)`);
    if (conus.type !== "scanlineimage" && conus.type !== "tiledimage") throw new Error(`not a valid CoNUS file: part conus is a ${conus.type} (V2)`);
    if (conus.window.xMin !== 0 || conus.window.yMin !== 0) throw new Error("not a valid CoNUS file: part conus's dataWindow does not start at (0,0) (V4)");
    const sourceSize = value(h, "conus:sourceSize", "v2i");
    if (!sourceSize || !(sourceSize[0] >= 1 && sourceSize[1] >= 1 && sourceSize[0] <= kMaxSide && sourceSize[1] <= kMaxSide))
      throw new Error("not a valid CoNUS file: conus:sourceSize missing or out of range (V5)");
    const mapIndex = parts.findIndex((p) => p.name === "samplingmap");
    if (mapIndex < 0) throw new Error("not a valid CoNUS file: no part samplingmap (V7)");
    const mp = parts[mapIndex];
    const n = mp.width, m = mp.height;
    if (mp.type !== "scanlineimage" || mp.window.xMin !== 0 || mp.window.yMin !== 0 || n < 2 || m < 2 || n > kMaxMapSide || m > kMaxMapSide)
      throw new Error(`not a valid CoNUS file: part samplingmap is not a scanline grid of 2..4097 nodes a side (V7)`);
    const mapBound = maxMapSideForImage(conus.width, conus.height);
    if (Math.max(n, m) > mapBound)
      throw new Error(`not a valid CoNUS file: a sampling map of ${n}x${m} nodes is finer than its ${conus.width}x${conus.height} ` +
        `image can show (at most ${mapBound} nodes a side, V7)`);
    const mapChannels = value(mp.header, "channels", "chlist") || [];
    if (mapChannels.length !== 2 || mapChannels[0].name !== "ud" || mapChannels[1].name !== "vd" ||
        mapChannels.some((c) => c.pixelType !== 2))
      throw new Error("not a valid CoNUS file: part samplingmap does not hold exactly the FLOAT channels ud and vd (V7)");
    // Before any pixel memory: what a browser tab can hold and a texture can show.
    const channelCount = (value(h, "channels", "chlist") || []).length;
    if (conus.width > maxSide || conus.height > maxSide || conus.width * conus.height * channelCount > maxValues)
      throw new Error(`the CoNUS image is ${conus.width}x${conus.height} of ${channelCount} channels, more than this page ` +
        `shows (${maxSide} a side, ${maxValues} values)`);
    const [image, grid] = await Promise.all([readPixels(bytes, conus, conusIndex), readPixels(bytes, mp, mapIndex)]);
    const nodes = new Float32Array(2 * n * m);
    for (let k = 0; k < n * m; ++k) {
      nodes[2 * k] = grid.planes[0][k];
      nodes[2 * k + 1] = grid.planes[1][k];
    }
    checkGrid(nodes, n, m);
    const fociValues = value(h, "conus:foci", "floatvector") || [];
    const foci = [];
    for (let k = 0; k + 3 < fociValues.length; k += 4) foci.push(fociValues.slice(k, k + 4));
    return {
      image: { ...image, half: image.pixelTypes.every((t) => t === 1) },
      map: { columns: n, rows: m, nodes },
      sourceSize,
      foci,
      mapKind: value(h, "conus:mapKind", "string") || "",
      compression: kCompressionNames[conus.compression],
    };
  }

  // A HALF plane's values as floats.
  function halfToFloat(plane) {
    const out = new Float32Array(plane.length);
    for (let i = 0; i < plane.length; ++i) out[i] = kHalfToFloat[plane[i]];
    return out;
  }

  return { readConus, readParts, halfToFloat, maxMapSideForImage };
})();
