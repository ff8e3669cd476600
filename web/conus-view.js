// The CoNUS viewer page: a CoNUS file (conus-exr.js) reconstructed by Equation 1 in WebGL2
// (conus-gl.js), and the view it shows: its size, pan and zoom by mouse, wheel, touch and keys,
// the file's loading, and remote frames under `conus serve`.
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

  const renderer = ConusGl.renderer(canvas);  // the WebGL2 drawing; null where the browser has none

  // ---- view state ----------------------------------------------------------------------------
  let frame = null;  // the frame shown (renderer.upload)
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

  // The frame at the view onto the canvas, every frame counted in window.conusFrames.
  let frames = 0;
  function draw() {
    if (!frame) return;
    resize();
    const moved = renderer.draw(frame, view, overlays);
    window.conusMoved = (window.conusMoved || 0) + (moved ? 1 : 0);  // frames drawn by moving the kept one
    ++frames;
    window.conusFrames = frames;
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
    const start = view.slice(), t0 = performance.now();
    for (let k = 1; k <= count; ++k) {
      view = movedView(kind, start, k);
      draw();
      renderer.finish();
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
    renderer.finish();  // waits for the frame
    renderer.checkErrors();
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
    const file = await ConusExr.readConus(bytes, { maxSide: renderer.maxTextureSize() });
    const t1 = performance.now();
    frame = renderer.upload(file, frame);
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
    if (!renderer) throw new Error("this browser has no WebGL2");
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