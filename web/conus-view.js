// The CoNUS viewer page: a CoNUS file (conus-exr.js) reconstructed by Equation 1 in WebGL2.
// Each canvas pixel takes its undistorted (u,v) in the view, the distorted position from the map's
// nodes, and one trilinear tap of the CoNUS image's pyramid: the desktop viewer's fragment shader
// (renderers/shaders/view_frame.frag.glsl, as GLSL ES in conus-shaders.js, written by `conus web`
// and `conus serve` from the same source), over the same mip chain as codec::buildPyramid (exact
// area halving), so the canvas is `conus decode --view` of the same view.
//
// Query: ?file=NAME (a CoNUS file beside the page), or ?picture=NAME under `conus serve` (frames
// encoded around where one looks); &view=u0,v0,u1,v1 &size=WxH draw that view at that size (the
// canvas then keeps it); &density=1, &outlines=1 start with those overlays.
// document.title is "ready" after the first complete frame and "error: ..." on failure.
"use strict";

(() => {
  const canvas = document.getElementById("view");
  const status = document.getElementById("status");
  const params = new URLSearchParams(location.search);

  function fail(error) {
    const text = String(error && error.message ? error.message : error).split("\n")[0];
    status.textContent = "error: " + text;
    status.className = "error";
    document.title = "error: " + text;
  }
  window.addEventListener("error", (e) => fail(e.message));
  window.addEventListener("unhandledrejection", (e) => fail(e.reason));

  function parseNumbers(text, count, what) {
    const values = text.split(",").map(Number);
    if (values.length !== count || !values.every(Number.isFinite)) throw new Error(`${what}: expected ${count} numbers, got "${text}"`);
    return values;
  }
  function parseSize(text) {
    const m = /^(\d+)x(\d+)$/.exec(text || "");
    if (!m || +m[1] < 1 || +m[2] < 1 || +m[1] > 8192 || +m[2] > 8192) throw new Error(`size: expected WxH of 1..8192, got "${text}"`);
    return [+m[1], +m[2]];
  }

  // ---- GL ----------------------------------------------------------------------------------
  const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: false, alpha: false, premultipliedAlpha: false });
  const floatLinear = gl && gl.getExtension("OES_texture_float_linear");
  const colorBufferFloat = gl && gl.getExtension("EXT_color_buffer_float");

  const kVertex = `#version 300 es
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}`;
  const programs = new Map();
  // A program of the full-screen triangle and `fragment`; a compile or link error is one line.
  function linkProgram(fragment) {
    const compile = (type, text) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error("shader: " + gl.getShaderInfoLog(s).split("\n")[0]);
      return s;
    };
    const p = gl.createProgram();
    gl.attachShader(p, compile(gl.VERTEX_SHADER, kVertex));
    gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fragment));
    gl.linkProgram(p);
    if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error("shader link: " + gl.getProgramInfoLog(p).split("\n")[0]);
    return p;
  }
  function program(mode, outlines) {
    const key = mode + "/" + outlines;
    if (programs.has(key)) return programs.get(key);
    const body = window.CONUS_VIEW_SHADER;
    if (!body) throw new Error("conus-shaders.js did not load");
    const p = linkProgram(`#version 300 es\n#define VIEW_MODE ${mode}\n#define VIEW_GRID 0\n#define VIEW_OUTLINES ${outlines ? 1 : 0}\n#define VIEW_PLAIN_DISPLAY 1\n` + body);
    const locations = new Map();
    const u = (name) => {
      if (!locations.has(name)) locations.set(name, gl.getUniformLocation(p, name));
      return locations.get(name);
    };
    const entry = { p, u };
    programs.set(key, entry);
    return entry;
  }

  // codec::buildPyramid's next level: the exact area average onto max(1, w/2) x max(1, h/2).
  function areaWeights(from, to) {
    const scale = from / to, list = [];
    for (let o = 0; o < to; ++o) {
      const a = o * scale, b = (o + 1) * scale, taps = [];
      for (let i = Math.floor(a); i < Math.min(from, Math.ceil(b)); ++i) {
        const w = (Math.min(b, i + 1) - Math.max(a, i)) / scale;
        if (w > 0) taps.push([i, w]);
      }
      list.push(taps);
    }
    return list;
  }
  function halve(level) {
    const w = Math.max(1, level.width >> 1), h = Math.max(1, level.height >> 1);
    if (level.width === 2 * w && level.height === 2 * h) {  // even sides: each texel the mean of four
      const out = new Float32Array(w * h * 4), src = level.data, stride = level.width * 4;
      for (let y = 0; y < h; ++y)
        for (let x = 0; x < w; ++x) {
          const s = 2 * y * stride + 8 * x, d = (y * w + x) * 4;
          for (let c = 0; c < 4; ++c)
            out[d + c] = 0.25 * ((src[s + c] + src[s + 4 + c]) + (src[s + stride + c] + src[s + stride + 4 + c]));
        }
      return { width: w, height: h, data: out };
    }
    const wx = areaWeights(level.width, w), wy = areaWeights(level.height, h);
    const rows = new Float32Array(w * level.height * 4), out = new Float32Array(w * h * 4);
    for (let y = 0; y < level.height; ++y)
      for (let x = 0; x < w; ++x) {
        let r = 0, g = 0, b = 0, a = 0;
        for (const [i, wt] of wx[x]) {
          const s = (y * level.width + i) * 4;
          r += wt * level.data[s]; g += wt * level.data[s + 1]; b += wt * level.data[s + 2]; a += wt * level.data[s + 3];
        }
        const d = (y * w + x) * 4;
        rows[d] = r; rows[d + 1] = g; rows[d + 2] = b; rows[d + 3] = a;
      }
    for (let y = 0; y < h; ++y)
      for (let x = 0; x < w; ++x) {
        let r = 0, g = 0, b = 0, a = 0;
        for (const [j, wt] of wy[y]) {
          const s = (j * w + x) * 4;
          r += wt * rows[s]; g += wt * rows[s + 1]; b += wt * rows[s + 2]; a += wt * rows[s + 3];
        }
        const d = (y * w + x) * 4;
        out[d] = r; out[d + 1] = g; out[d + 2] = b; out[d + 3] = a;
      }
    return { width: w, height: h, data: out };
  }

  // The display channels as RGBA, as the desktop viewer takes them: R,G,B(,A), else Y (or the first
  // channel) as grey. HALF channels stay 16-bit (Uint16Array, uploaded as they are) when all four
  // are; otherwise floats.
  function displayRgba(image) {
    const index = (name) => image.channels.indexOf(name);
    let src = [index("R"), index("G"), index("B")];
    if (src.some((i) => i < 0)) {
      const grey = index("Y") >= 0 ? index("Y") : 0;
      src = [grey, grey, grey];
    }
    const alpha = index("A");
    const used = alpha >= 0 ? [...src, alpha] : src;
    const half = used.every((i) => image.pixelTypes[i] === 1);
    const plane = (i) => (half || image.pixelTypes[i] !== 1 ? image.planes[i] : ConusExr.halfToFloat(image.planes[i]));
    const n = image.width * image.height, data = half ? new Uint16Array(n * 4) : new Float32Array(n * 4);
    const [pr, pg, pb] = src.map(plane);
    const pa = alpha >= 0 ? plane(alpha) : null;
    const one = half ? 0x3c00 : 1;
    for (let k = 0, d = 0; k < n; ++k, d += 4) {
      data[d] = pr[k]; data[d + 1] = pg[k]; data[d + 2] = pb[k]; data[d + 3] = pa ? pa[k] : one;
    }
    return { width: image.width, height: image.height, data, half };
  }

  // The pyramid's levels 1.. drawn by the GPU, each from the one below: codec::buildPyramid's exact
  // area average onto max(1, w/2) x max(1, h/2), its weights in integers (a texel's overlap with
  // the one below, at most 3 a side where a side is odd). Needs a float colour target
  // (EXT_color_buffer_float); without one, halve() in JavaScript.
  const kPyramidFragment = `#version 300 es
precision highp float;
precision highp int;
precision highp sampler2D;
uniform sampler2D uBelow;  // its base level is the level below
out vec4 fragColor;
// Texels of the level below (from texels) under texel x of this level (to texels) and their weights.
void taps(int x, int from, int to, out ivec3 i, out vec3 w) {
    const int a = x * from, b = (x + 1) * from;
    const int first = a / to;
    for (int k = 0; k < 3; ++k) {
        const int j = first + k;
        i[k] = min(j, from - 1);
        w[k] = j < from ? float(max(0, min(b, (j + 1) * to) - max(a, j * to))) / float(from) : 0.0;
    }
}
void main() {
    const ivec2 from = textureSize(uBelow, 0);
    const ivec2 p = ivec2(gl_FragCoord.xy);
#if EVEN
    // Both sides even: the mean of four texels is one bilinear tap at their shared corner.
    fragColor = textureLod(uBelow, vec2(2 * p + 1) / vec2(from), 0.0);
    return;
#endif
    const ivec2 to = max(from / 2, ivec2(1));
    ivec3 ix, iy;
    vec3 wx, wy;
    taps(p.x, from.x, to.x, ix, wx);
    taps(p.y, from.y, to.y, iy, wy);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < 3; ++j) {
        if (wy[j] == 0.0) continue;
        vec4 row = vec4(0.0);
        for (int i = 0; i < 3; ++i)
            if (wx[i] != 0.0) row += wx[i] * texelFetch(uBelow, ivec2(ix[i], iy[j]), 0);
        sum += wy[j] * row;
    }
    fragColor = sum;
}`.replace(/\n( +)const /g, "\n$1");
  const pyramidPrograms = [];
  function drawPyramid(texture, width, height, levels) {
    const pyramidProgram = (even) => {
      if (pyramidPrograms[even]) return pyramidPrograms[even];
      const p = linkProgram(kPyramidFragment.replace("\n", `\n#define EVEN ${even}\n`));
      gl.useProgram(p);
      gl.uniform1i(gl.getUniformLocation(p, "uBelow"), 0);
      return (pyramidPrograms[even] = p);
    };
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR);
    for (let k = 1; k < levels; ++k) {
      const w = Math.max(1, width >> (k - 1)), h = Math.max(1, height >> (k - 1));
      gl.useProgram(pyramidProgram(w % 2 === 0 && h % 2 === 0 ? 1 : 0));
      // Sampling only level k-1 while level k is the target: no feedback loop.
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_BASE_LEVEL, k - 1);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, k - 1);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture, k);
      if (k === 1 && gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) {
        gl.bindFramebuffer(gl.FRAMEBUFFER, null);
        gl.deleteFramebuffer(fb);
        return false;
      }
      gl.viewport(0, 0, Math.max(1, width >> k), Math.max(1, height >> k));
      gl.drawArrays(gl.TRIANGLES, 0, 3);
    }
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_BASE_LEVEL, 0);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAX_LEVEL, levels - 1);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.deleteFramebuffer(fb);
    return true;
  }

  function densityRange(map) {
    // log det J at 128 x 128 points, as the desktop viewer's heat map takes its range.
    const n = map.columns, m = map.rows, N = map.nodes, S = 128;
    let lo = Infinity, hi = -Infinity;
    for (let j = 0; j < S; ++j)
      for (let i = 0; i < S; ++i) {
        const gx = (i + 0.5) / S * (n - 1), gy = (j + 0.5) / S * (m - 1);
        const ci = Math.min(Math.floor(gx), n - 2), cj = Math.min(Math.floor(gy), m - 2), s = gx - ci, t = gy - cj;
        const node = (a, b, c) => N[2 * ((cj + b) * n + ci + a) + c];
        const du = [0, 1].map((c) => ((1 - t) * (node(1, 0, c) - node(0, 0, c)) + t * (node(1, 1, c) - node(0, 1, c))) * (n - 1));
        const dv = [0, 1].map((c) => ((1 - s) * (node(0, 1, c) - node(0, 0, c)) + s * (node(1, 1, c) - node(1, 0, c))) * (m - 1));
        const d = Math.log(Math.max(du[0] * dv[1] - du[1] * dv[0], 1e-12));
        lo = Math.min(lo, d); hi = Math.max(hi, d);
      }
    return [lo, hi];
  }

  let frame = null;  // {conus: texture, map: texture, sourceSize, foci, logDensity}
  function upload(file) {
    const max = gl.getParameter(gl.MAX_TEXTURE_SIZE);
    if (file.image.width > max || file.image.height > max)
      throw new Error(`the CoNUS image is ${file.image.width}x${file.image.height}, larger than this browser's largest texture (${max})`);
    // RGBA32F where it filters (a float file's values as they are), else RGBA16F: half's step is a
    // tenth of 8-bit sRGB's finest.
    let level = displayRgba(file.image);
    const internal = floatLinear && !level.half ? gl.RGBA32F : gl.RGBA16F;
    const conus = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, conus);
    const levels = Math.floor(Math.log2(Math.max(level.width, level.height))) + 1;
    gl.texStorage2D(gl.TEXTURE_2D, levels, internal, level.width, level.height);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 4);
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, level.width, level.height, gl.RGBA, level.half ? gl.HALF_FLOAT : gl.FLOAT, level.data);
    if (levels > 1 && !(colorBufferFloat && drawPyramid(conus, level.width, level.height, levels))) {
      if (level.half) level = { ...level, data: ConusExr.halfToFloat(level.data) };
      for (let k = 1; k < levels; ++k) {
        level = halve(level);
        gl.texSubImage2D(gl.TEXTURE_2D, k, 0, 0, level.width, level.height, gl.RGBA, gl.FLOAT, level.data);
      }
    }
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.LINEAR_MIPMAP_LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.LINEAR);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_S, gl.CLAMP_TO_EDGE);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_WRAP_T, gl.CLAMP_TO_EDGE);
    const map = gl.createTexture();
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, map);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RG32F, file.map.columns, file.map.rows);
    gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, file.map.columns, file.map.rows, gl.RG, gl.FLOAT, file.map.nodes);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    if (frame) { gl.deleteTexture(frame.conus); gl.deleteTexture(frame.map); }
    frame = { id: (frame ? frame.id : 0) + 1, conus, map, sourceSize: file.sourceSize, foci: file.foci, logDensity: densityRange(file.map) };
  }

  // ---- view state ----------------------------------------------------------------------------
  let view = null;  // [u0, v0, u1, v1]
  const overlays = { density: params.get("density") === "1", outlines: params.get("outlines") === "1" };
  const fixedSize = params.has("size") ? parseSize(params.get("size")) : null;

  function resize() {
    const [w, h] = fixedSize || [Math.max(1, Math.round(canvas.clientWidth * devicePixelRatio)),
                                 Math.max(1, Math.round(canvas.clientHeight * devicePixelRatio))];
    if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
    if (fixedSize) { canvas.style.width = w / devicePixelRatio + "px"; canvas.style.height = h / devicePixelRatio + "px"; }
  }

  // The whole frame, centred, at the canvas's aspect (source pixels square).
  function wholeView() {
    const [sw, sh] = frame.sourceSize, aspect = (canvas.width / canvas.height) / (sw / sh);
    if (aspect >= 1) return [0.5 - aspect / 2, 0, 0.5 + aspect / 2, 1];
    return [0, 0.5 - 0.5 / aspect, 1, 0.5 + 0.5 / aspect];
  }

  // `v` widened about its centre to the canvas's aspect (source pixels square): a view given
  // without a size, and the view after the window resizes.
  function fitAspect(v) {
    const [sw, sh] = frame.sourceSize, want = canvas.width / canvas.height;
    const w = (v[2] - v[0]) * sw, h = (v[3] - v[1]) * sh, cu = (v[0] + v[2]) / 2, cv = (v[1] + v[3]) / 2;
    if (w / h < want) { const hu = (h * want / sw) / 2; return [cu - hu, v[1], cu + hu, v[3]]; }
    const hv = (w / want / sh) / 2;
    return [v[0], cv - hv, v[2], cv + hv];
  }

  let pending = false;
  function requestDraw() {
    if (pending) return;
    pending = true;
    requestAnimationFrame(() => { pending = false; draw(); });
  }

  // A pan by whole pixels at the same scale moves the frame on the canvas (kept there by
  // preserveDrawingBuffer): blitted into an offscreen target of its size and back, moved (exact
  // copies), and Equation 1 drawn only on the strips the move uncovers. Each pixel keeps the
  // value the shader gives it at its (u,v), so the canvas is the one a full draw makes. Anything
  // else (a zoom, another overlay, another frame, a resize) draws every pixel onto the canvas.
  // RGB8: the canvas has no alpha, and a copy may not add a channel.
  const kept = { target: null, view: null, key: "" };
  function target() {
    const t = kept.target;
    if (t && t.width === canvas.width && t.height === canvas.height) return t;
    if (t) { gl.deleteFramebuffer(t.fb); gl.deleteTexture(t.texture); }
    const texture = gl.createTexture();
    gl.activeTexture(gl.TEXTURE2);
    gl.bindTexture(gl.TEXTURE_2D, texture);
    gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGB8, canvas.width, canvas.height);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, texture, 0);
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    return (kept.target = { fb, texture, width: canvas.width, height: canvas.height });
  }

  // The whole-pixel move (x right, y up, GL's window coordinates) from the kept frame to `view`,
  // or null where the kept frame cannot be moved there (another scale, a fraction of a pixel off,
  // nothing kept).
  function pixelShift(key) {
    const k = kept.view;
    if (!k || kept.key !== key) return null;
    const w = canvas.width, h = canvas.height, sx = (k[2] - k[0]) / w, sy = (k[3] - k[1]) / h;
    if (Math.abs((view[2] - view[0]) / w - sx) > 1e-9 * Math.abs(sx) || Math.abs((view[3] - view[1]) / h - sy) > 1e-9 * Math.abs(sy)) return null;
    const n = (view[0] - k[0]) / sx, m = (view[1] - k[1]) / sy;
    if (Math.abs(n - Math.round(n)) > 1e-3 || Math.abs(m - Math.round(m)) > 1e-3) return null;
    const dx = -Math.round(n), dy = Math.round(m);  // the kept picture moves by (dx, dy); rows grow downward in v
    return Math.abs(dx) < w && Math.abs(dy) < h ? [dx, dy] : null;
  }

  let frames = 0;
  function draw() {
    if (!frame) return;
    resize();
    const key = `${overlays.density ? 4 : 0}/${overlays.outlines}/${frame.id}`;
    const { p, u } = program(overlays.density ? 4 : 0, overlays.outlines);
    const w = canvas.width, h = canvas.height;
    const shift = canvas.width === kept.width && canvas.height === kept.height ? pixelShift(key) : null;
    gl.bindFramebuffer(gl.FRAMEBUFFER, null);
    gl.viewport(0, 0, w, h);
    if (shift) {
      // The canvas into the target, back onto the canvas moved by (dx, dy); the strips it leaves, drawn.
      const [dx, dy] = shift, t = target();
      gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, t.fb);
      gl.blitFramebuffer(0, 0, w, h, 0, 0, w, h, gl.COLOR_BUFFER_BIT, gl.NEAREST);  // copyTexSubImage2D: 2.8x slower on SwiftShader
      gl.bindFramebuffer(gl.DRAW_FRAMEBUFFER, null);
      const x0 = Math.max(0, dx), x1 = Math.min(w, w + dx), y0 = Math.max(0, dy), y1 = Math.min(h, h + dy);
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, t.fb);
      gl.blitFramebuffer(x0 - dx, y0 - dy, x1 - dx, y1 - dy, x0, y0, x1, y1, gl.COLOR_BUFFER_BIT, gl.NEAREST);
      gl.bindFramebuffer(gl.READ_FRAMEBUFFER, null);
      gl.enable(gl.SCISSOR_TEST);  // after the blit, which the scissor would clip too
      const strips = [];
      if (dx > 0) strips.push([0, 0, dx, h]); else if (dx < 0) strips.push([w + dx, 0, -dx, h]);
      if (dy > 0) strips.push([0, 0, w, dy]); else if (dy < 0) strips.push([0, h + dy, w, -dy]);
      for (const [x, y, sw, sh] of strips) {
        gl.scissor(x, y, sw, sh);
        drawEquation1(p, u);
      }
      gl.disable(gl.SCISSOR_TEST);
    } else {
      drawEquation1(p, u);
    }
    kept.view = view.slice();
    kept.width = w;
    kept.height = h;
    kept.key = key;
    window.conusMoved = (window.conusMoved || 0) + (shift ? 1 : 0);  // frames drawn by moving the kept one
    ++frames;
    window.conusFrames = frames;
  }

  // Equation 1 over the bound target's viewport (and scissor): the frame of `view`.
  function drawEquation1(p, u) {
    gl.useProgram(p);
    gl.activeTexture(gl.TEXTURE0);
    gl.bindTexture(gl.TEXTURE_2D, frame.conus);
    gl.activeTexture(gl.TEXTURE1);
    gl.bindTexture(gl.TEXTURE_2D, frame.map);
    gl.uniform1i(u("uConus"), 0);
    gl.uniform1i(u("uMap"), 1);
    gl.uniform1i(u("uUniform"), 0);
    gl.uniform4f(u("uView"), view[0], view[1], view[2], view[3]);
    gl.uniform2f(u("uOutputSize"), canvas.width, canvas.height);
    gl.uniform1i(u("uBottomUp"), 1);
    gl.uniform2f(u("uGridLines"), 0, 0);
    gl.uniform2f(u("uSourceSize"), frame.sourceSize[0], frame.sourceSize[1]);
    const foci = frame.foci.slice(0, 16);
    gl.uniform1i(u("uFocusCount"), foci.length);
    if (foci.length) gl.uniform3fv(u("uFoci"), new Float32Array(foci.flatMap((f) => [f[0], f[1], f[2]])));
    gl.uniform1f(u("uWipeX"), 0);
    gl.uniform2f(u("uLogDensity"), frame.logDensity[0], frame.logDensity[1]);
    gl.drawArrays(gl.TRIANGLES, 0, 3);
  }

  // For tests: the view drawn now, and how many frames the page has asked `conus serve` for.
  window.conusView = () => view && view.slice();

  // For the benches: the view of frame k of a move about `start`. "pan": a drag, whole pixels a
  // frame at the same scale; "zoom": the scale alone, about the centre; "both": a zoom and pan at
  // once, every frame at another scale.
  function movedView(kind, start, k) {
    const w = canvas.width, h = canvas.height, su = (start[2] - start[0]) / w, sv = (start[3] - start[1]) / h;
    if (kind === "pan") {
      const x = Math.round(60 * Math.sin(k / 9)), y = Math.round(40 * Math.cos(k / 7) - 40);  // pixels from the start
      return [start[0] + x * su, start[1] + y * sv, start[2] + x * su, start[3] + y * sv];
    }
    const s = Math.exp(-0.5 * Math.sin(k / 9));
    const du = kind === "both" ? 0.1 * Math.sin(k / 13) : 0, dv = kind === "both" ? 0.1 * Math.cos(k / 11) : 0;
    const cu = (start[0] + start[2]) / 2 + du, cv = (start[1] + start[3]) / 2 + dv;
    const hw = (start[2] - start[0]) / 2 * s, hh = (start[3] - start[1]) / 2 * s;
    return [cu - hw, cv - hh, cu + hw, cv + hh];
  }
  // `count` frames of a move ("pan", "zoom" or "both", above), each drawn and waited for (a one-pixel
  // read), in frames a second; the view is put back.
  window.conusPanZoomRate = (count, kind = "both") => {
    const start = view.slice(), pixel = new Uint8Array(4), t0 = performance.now();
    for (let k = 1; k <= count; ++k) {
      view = movedView(kind, start, k);
      draw();
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    }
    const seconds = (performance.now() - t0) / 1000;
    view = start;
    draw();
    return count / seconds;
  };
  // The same move, one frame an animation frame, so that the browser shows each (its compositing
  // counted): a promise of the frames a second shown.
  window.conusShownRate = (count, kind = "both") => new Promise((resolve) => {
    const start = view.slice();
    let k = 0, t0 = 0;
    const step = () => {
      if (k === 0) t0 = performance.now();
      if (k === count) {
        const rate = count / ((performance.now() - t0) / 1000);
        view = start;
        draw();
        resolve(rate);
        return;
      }
      view = movedView(kind, start, ++k);
      draw();
      requestAnimationFrame(step);
    };
    requestAnimationFrame(step);
  });

  function finishFirstFrame() {
    const t0 = performance.now();
    draw();
    const pixel = new Uint8Array(4);
    gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);  // waits for the frame
    const error = gl.getError();
    if (error !== gl.NO_ERROR) throw new Error("WebGL error " + error);
    window.conusTimings.firstDraw = performance.now() - t0;
    if (window.conusReadyAt === undefined) window.conusReadyAt = performance.now();  // ms after navigation began
    document.title = "ready";
    status.textContent = statusText();
  }

  let statusBase = "";
  function statusText() {
    if (!view) return statusBase;
    return `${statusBase} · view ${view.map((x) => x.toFixed(3)).join(",")} · drag, wheel, pinch; d density, f foci, 0 whole` +
      (remote ? "; double-click: a sharp frame there" : "");
  }

  // ---- interaction ---------------------------------------------------------------------------
  function uvAt(clientX, clientY) {
    const r = canvas.getBoundingClientRect();
    const x = (clientX - r.left) / r.width, y = (clientY - r.top) / r.height;
    return [view[0] + x * (view[2] - view[0]), view[1] + y * (view[3] - view[1]), x, y];
  }
  function zoomAt(clientX, clientY, factor) {
    const [u, v, x, y] = uvAt(clientX, clientY);
    const w = (view[2] - view[0]) * factor, h = (view[3] - view[1]) * factor;
    if (w < 1e-5 || w > 64) return;
    view = [u - x * w, v - y * h, u - x * w + w, v - y * h + h];
    changed();
  }
  // A drag of (dx, dy) CSS pixels moves the view by whole canvas pixels (the rest is carried to
  // the next move), so that the frame kept on the GPU is moved and not drawn again (draw()).
  const panRest = [0, 0];
  function panBy(dx, dy) {
    const r = canvas.getBoundingClientRect();
    panRest[0] += dx / r.width * canvas.width;
    panRest[1] += dy / r.height * canvas.height;
    const px = Math.round(panRest[0]), py = Math.round(panRest[1]);
    panRest[0] -= px;
    panRest[1] -= py;
    const du = px * (view[2] - view[0]) / canvas.width, dv = py * (view[3] - view[1]) / canvas.height;
    view = [view[0] - du, view[1] - dv, view[2] - du, view[3] - dv];
    changed();
  }
  let settle = 0;
  function changed() {
    requestDraw();
    status.textContent = statusText();
    if (remote) {
      clearTimeout(settle);
      settle = setTimeout(() => remote.lookAt((view[0] + view[2]) / 2, (view[1] + view[3]) / 2), 400);
    }
  }

  let drag = null;
  canvas.addEventListener("pointerdown", (e) => { if (e.pointerType !== "touch") { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); } });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag || !view) return;
    panBy(e.clientX - drag[0], e.clientY - drag[1]);
    drag = [e.clientX, e.clientY];
  });
  canvas.addEventListener("pointerup", () => { drag = null; });
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    if (view) zoomAt(e.clientX, e.clientY, Math.exp(e.deltaY * (e.deltaMode ? 0.05 : 0.0015)));
  }, { passive: false });
  canvas.addEventListener("dblclick", (e) => {
    if (!view) return;
    const [u, v] = uvAt(e.clientX, e.clientY);
    if (remote) { clearTimeout(settle); remote.lookAt(u, v); }
    else zoomAt(e.clientX, e.clientY, 0.5);
  });
  let touches = null;
  const touchState = (list) => {
    const t = Array.from(list);
    const cx = t.reduce((s, p) => s + p.clientX, 0) / t.length, cy = t.reduce((s, p) => s + p.clientY, 0) / t.length;
    const spread = t.length > 1 ? Math.hypot(t[0].clientX - t[1].clientX, t[0].clientY - t[1].clientY) : 0;
    return { n: t.length, cx, cy, spread };
  };
  canvas.addEventListener("touchstart", (e) => { e.preventDefault(); touches = touchState(e.touches); }, { passive: false });
  canvas.addEventListener("touchmove", (e) => {
    e.preventDefault();
    if (!view || !touches) return;
    const now = touchState(e.touches);
    if (now.n === touches.n) {
      panBy(now.cx - touches.cx, now.cy - touches.cy);
      if (now.n > 1 && touches.spread > 0 && now.spread > 0) zoomAt(now.cx, now.cy, touches.spread / now.spread);
    }
    touches = now;
  }, { passive: false });
  canvas.addEventListener("touchend", (e) => { touches = e.touches.length ? touchState(e.touches) : null; });
  window.addEventListener("keydown", (e) => {
    if (!view) return;
    if (e.key === "d") overlays.density = !overlays.density;
    else if (e.key === "f") overlays.outlines = !overlays.outlines;
    else if (e.key === "0") view = wholeView();
    else return;
    changed();
  });
  window.addEventListener("resize", () => {
    if (fixedSize || !view) return;
    resize();
    view = fitAspect(view);
    changed();
  });

  // ---- loading -------------------------------------------------------------------------------
  // Bytes of a file beside the page: fetched over HTTP; opened from disk (file://, where fetch
  // cannot read), from the NAME.js that `conus web` writes beside it.
  async function fileBytes(name) {
    if (location.protocol !== "file:") {
      const response = await fetch(name.split("/").map(encodeURIComponent).join("/"));
      if (!response.ok) throw new Error(`${name}: ${response.status} ${(await response.text()).split("\n")[0] || response.statusText}`);
      return new Uint8Array(await response.arrayBuffer());
    }
    await new Promise((resolve, reject) => {
      const s = document.createElement("script");
      s.src = name + ".js";
      s.onload = resolve;
      s.onerror = () => reject(new Error(`${name}: cannot be read from this folder (${name}.js is missing)`));
      document.head.appendChild(s);
    });
    const text = atob((window.CONUS_FILES || {})[name] || "");
    const bytes = new Uint8Array(text.length);
    for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
    return bytes;
  }

  // Where the first frame's time went (ms), for bench/web_bench.py.
  window.conusTimings = {};
  async function show(bytes, label) {
    const t0 = performance.now();
    const file = await ConusExr.readConus(bytes, { maxSide: gl.getParameter(gl.MAX_TEXTURE_SIZE) });
    const t1 = performance.now();
    upload(file);
    Object.assign(window.conusTimings, { parse: t1 - t0, upload: performance.now() - t1 });
    statusBase = `${label}: ${file.image.width}x${file.image.height} CoNUS image of a ${file.sourceSize[0]}x${file.sourceSize[1]} frame`;
    if (!view) {
      view = params.has("view") ? parseNumbers(params.get("view"), 4, "view") : wholeView();
      if (view[0] === view[2] || view[1] === view[3]) throw new Error("view: empty");
      if (!fixedSize) view = fitAspect(view);  // with a size the view is drawn as given, as conus decode does
    }
    finishFirstFrame();
  }

  // Remote viewing under `conus serve`: a frame encoded around where one looks, the last one shown
  // until the next arrives.
  let remote = null;
  function makeRemote(picture) {
    let wanted = null, busy = false, lastKey = "";
    const frameSize = params.get("frame") || "1024x1024";
    parseSize(frameSize);
    async function fetchFrame() {
      if (busy || !wanted) return;
      const [u, v] = wanted;
      wanted = null;
      const w = view ? view[2] - view[0] : 1;
      const r = Math.min(0.5, Math.max(0.01, w / 4));
      // Samples the view needs along u at its centre over what a uniform frame gives.
      const [fw] = frameSize.split("x").map(Number);
      const k = frame ? Math.min(16, Math.max(1, Math.min(frame.sourceSize[0], canvas.width / w) / fw * 2)) : 4;
      const focus = [u, v, r, k].map((x) => +x.toFixed(4)).join(",");
      const key = `frame?file=${encodeURIComponent(picture)}&focus=${focus}&size=${frameSize}`;
      if (key === lastKey) return;
      busy = true;
      status.textContent = statusText() + " · asking for a frame at " + focus;
      try {
        const response = await fetch(key);
        if (!response.ok) throw new Error(`frame: ${response.status} ${(await response.text()).split("\n")[0]}`);
        const bytes = new Uint8Array(await response.arrayBuffer());
        lastKey = key;
        await show(bytes, `${picture} (${Math.round(bytes.length / 1024)} KB frame, focus ${focus})`);
      } finally {
        busy = false;
        if (wanted) fetchFrame();
      }
    }
    return {
      lookAt(u, v) {
        wanted = [Math.min(1, Math.max(0, u)), Math.min(1, Math.max(0, v))];
        fetchFrame().catch(fail);
      },
    };
  }

  async function start() {
    if (!gl) throw new Error("this browser has no WebGL2");
    resize();
    if (params.has("picture")) {
      remote = makeRemote(params.get("picture"));
      const initial = params.has("view") ? parseNumbers(params.get("view"), 4, "view") : [0, 0, 1, 1];
      remote.lookAt((initial[0] + initial[2]) / 2, (initial[1] + initial[3]) / 2);
      return;
    }
    const name = params.get("file") || document.body.dataset.file;
    if (!name) throw new Error("no file: open the page with ?file=NAME.exr");
    const t0 = performance.now();
    const bytes = await fileBytes(name);
    window.conusTimings.fetch = performance.now() - t0;
    await show(bytes, name);
  }
  start().catch(fail);
})();
