// The CoNUS viewer's WebGL2 drawing: a CoNUS file (conus-exr.js) uploaded as textures and
// reconstructed by Equation 1. Each canvas pixel takes its undistorted (u,v) in the view, the
// distorted position from the map's nodes, and one trilinear tap of the CoNUS image's pyramid: the
// desktop viewer's fragment shader (renderers/shaders/view_frame.frag.glsl, as GLSL ES in
// conus-shaders.js, written by `conus web` and `conus serve` from the same source), over the same
// mip chain as codec::buildPyramid (exact area halving), so the canvas is `conus decode --view` of
// the same view. A pan by whole pixels moves the frame already on the canvas.
"use strict";

const ConusGl = (() => {
  const kVertex = `#version 300 es
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 0.0, 1.0);
}`;

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

  // A renderer on `canvas`'s WebGL2 context; null where the browser has none.
  function renderer(canvas) {
    const gl = canvas.getContext("webgl2", { preserveDrawingBuffer: true, antialias: false, alpha: false, premultipliedAlpha: false });
    if (!gl) return null;
    const floatLinear = gl.getExtension("OES_texture_float_linear");
    const colorBufferFloat = gl.getExtension("EXT_color_buffer_float");

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

    const maxTextureSize = () => gl.getParameter(gl.MAX_TEXTURE_SIZE);

    // `file` (ConusExr.readConus) as the frame drawn from now on: {id, conus: texture, map: texture,
    // sourceSize, foci, logDensity}; the textures of `previous` (the frame before, or null) deleted.
    function upload(file, previous) {
      const max = maxTextureSize();
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
      if (previous) { gl.deleteTexture(previous.conus); gl.deleteTexture(previous.map); }
      return { id: (previous ? previous.id : 0) + 1, conus, map, sourceSize: file.sourceSize, foci: file.foci, logDensity: densityRange(file.map) };
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
    function pixelShift(view, key) {
      const k = kept.view;
      if (!k || kept.key !== key) return null;
      const w = canvas.width, h = canvas.height, sx = (k[2] - k[0]) / w, sy = (k[3] - k[1]) / h;
      if (Math.abs((view[2] - view[0]) / w - sx) > 1e-9 * Math.abs(sx) || Math.abs((view[3] - view[1]) / h - sy) > 1e-9 * Math.abs(sy)) return null;
      const n = (view[0] - k[0]) / sx, m = (view[1] - k[1]) / sy;
      if (Math.abs(n - Math.round(n)) > 1e-3 || Math.abs(m - Math.round(m)) > 1e-3) return null;
      const dx = -Math.round(n), dy = Math.round(m);  // the kept picture moves by (dx, dy); rows grow downward in v
      return Math.abs(dx) < w && Math.abs(dy) < h ? [dx, dy] : null;
    }

    // `frame` at `view` [u0, v0, u1, v1] onto the whole canvas, with `overlays` {density, outlines};
    // true where the kept frame was moved and only the strips it uncovers were drawn.
    function draw(frame, view, overlays) {
      const key = `${overlays.density ? 4 : 0}/${overlays.outlines}/${frame.id}`;
      const { p, u } = program(overlays.density ? 4 : 0, overlays.outlines);
      const w = canvas.width, h = canvas.height;
      const shift = canvas.width === kept.width && canvas.height === kept.height ? pixelShift(view, key) : null;
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
          drawEquation1(frame, view, p, u);
        }
        gl.disable(gl.SCISSOR_TEST);
      } else {
        drawEquation1(frame, view, p, u);
      }
      kept.view = view.slice();
      kept.width = w;
      kept.height = h;
      kept.key = key;
      return shift !== null;
    }

    // Equation 1 over the bound target's viewport (and scissor): `frame` at `view`.
    function drawEquation1(frame, view, p, u) {
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

    const pixel = new Uint8Array(4);
    // Waits for the frames drawn: a one-pixel read.
    const finish = () => gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
    // Throws where WebGL has an error to report.
    function checkErrors() {
      const error = gl.getError();
      if (error !== gl.NO_ERROR) throw new Error("WebGL error " + error);
    }

    return { maxTextureSize, upload, draw, finish, checkErrors };
  }

  return { renderer };
})();
