// pyjulia4d explore: the page's side of the WebSocket protocol (pyjulia4d/app/explore/session.py).
// Every control is a form element named by its scene key; a slider with data-for types into its
// field. Moves are gathered per animation frame and sent as one request; the server renders the
// latest request only and refines the picture once the controls rest.
"use strict";
(() => {
  const form = document.getElementById("controls");
  const view = document.getElementById("view");
  const picture = document.getElementById("picture");
  const errorLine = document.getElementById("error");
  const statusLine = document.getElementById("status");
  const facts = document.getElementById("facts");
  const turn = document.getElementById("turn-w");
  const progress = document.getElementById("file-progress");
  const DATA = window.PYJULIA4D || { functions: {} };
  const DEGREES_PER_PIXEL = 0.4;
  const TYPING_PAUSE_MS = 600;

  let ws = null;
  let everConnected = false;
  let frameMeta = null;        // the message announcing the picture whose bytes come next
  let pictures = 0;
  let shownUrl = null;
  const pendingValues = {};    // control values changed since the last flush
  let pendingMoving = false;
  let orbit = { yaw: 0, pitch: 0 }, wTurn = 0, zoom = 1;
  let flushQueued = false;
  let restTimer = null;

  function send(message) {
    if (ws && ws.readyState === WebSocket.OPEN) ws.send(JSON.stringify(message));
  }

  function showError(text) {
    errorLine.textContent = text;
    const name = text.split(": ")[0];
    const el = form.elements.namedItem(name);
    if (el && el.classList) el.classList.add("invalid");
  }

  function clearError() { errorLine.textContent = ""; }

  function setValue(name, value) {
    const el = form.elements.namedItem(name);
    if (!el) return;
    if (el.tagName === "SELECT" && name === "fractal.function") fillFunctions(form.elements.namedItem("fractal.algebra").value);
    el.value = value;
    el.classList.remove("invalid");
    const slider = form.querySelector(`input[type=range][data-for="${CSS.escape(name)}"]`);
    if (slider) slider.value = value;
  }

  // the picture's box: the scene's image size in CSS pixels (at most the column's width), so
  // that a preview, smaller, is stretched to the size of the picture it stands for
  function sizeView() {
    const w = Number(form.elements.namedItem("image.width").value);
    const h = Number(form.elements.namedItem("image.height").value);
    if (w > 0 && h > 0) { view.style.width = `${w}px`; view.style.aspectRatio = `${w} / ${h}`; }
  }

  function allValues() {
    const out = {};
    for (const el of form.elements) if (el.name) out[el.name] = el.value;
    return out;
  }

  function fillFunctions(algebra) {
    const select = form.elements.namedItem("fractal.function");
    const names = DATA.functions[algebra] || [];
    const keep = names.includes(select.value) ? select.value : names[0];
    select.replaceChildren(...names.map((n) => new Option(n, n, false, n === keep)));
    select.value = keep;
  }

  function renderFacts(f) {
    const rows = [["stage", f.stage], ["size", f.size], ["render time", f.seconds + " s"], ["pixels hit", f.hit],
      ["depth bracket", f.bracket], ["depth error", f.error], ["unresolved", f.unresolved],
      ["capped rays", f.capped], ["guards fired", f.guards], ["device", f.device]];
    if (f.noise) rows.splice(3, 0, ["noise", f.noise], ["paths per pixel", f.paths]);
    facts.replaceChildren(...rows.flatMap(([k, v]) => {
      const dt = document.createElement("dt"); dt.textContent = k;
      const dd = document.createElement("dd"); dd.textContent = v;
      return [dt, dd];
    }));
  }

  function onPicture(blob) {
    const meta = frameMeta || {};
    sizeView();
    frameMeta = null;
    const url = URL.createObjectURL(blob);
    const old = shownUrl;
    shownUrl = url;
    view.onload = () => { if (old) URL.revokeObjectURL(old); };
    view.src = url;
    pictures += 1;
    view.dataset.stage = meta.stage || "";
    view.dataset.generation = String(meta.generation || 0);
    view.dataset.count = String(pictures);
    if (meta.facts) renderFacts(meta.facts);
  }

  function onMessage(m) {
    switch (m.type) {
      case "frame": frameMeta = m; break;
      case "values": for (const [k, v] of Object.entries(m.values)) setValue(k, v); sizeView(); break;
      case "error": showError(m.message); break;
      case "status": statusLine.textContent = m.message; break;
      case "progress":
        progress.hidden = m.done >= 1;
        progress.value = m.done;
        statusLine.textContent = `rendering ${m.name}: ${Math.round(100 * m.done)} %`;
        break;
      case "keyframes":
        document.getElementById("keyframe-count").textContent =
          `${m.count} keyframe${m.count === 1 ? "" : "s"}` + (m.count ? `, the last at frame ${m.frame ?? 0}` : "");
        break;
    }
  }

  function connect() {
    ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
    ws.binaryType = "blob";
    ws.onopen = () => {
      statusLine.textContent = "connected";
      if (everConnected) send({ op: "set", values: allValues() });   // a new session: the page's view
      everConnected = true;
    };
    ws.onmessage = (ev) => {
      if (typeof ev.data === "string") {
        let m;
        try { m = JSON.parse(ev.data); } catch (e) { showError("unreadable message from the server"); return; }
        onMessage(m);
      } else {
        onPicture(ev.data);
      }
    };
    ws.onclose = () => {
      showError("the connection to the server was lost; reconnecting…");
      setTimeout(connect, 1000);
    };
  }

  // ---------------------------------------------------------------- gathering requests

  function queueFlush() {
    if (!flushQueued) { flushQueued = true; requestAnimationFrame(flush); }
  }

  function flush() {
    flushQueued = false;
    const names = Object.keys(pendingValues);
    if (names.length) {
      const values = {};
      for (const n of names) { values[n] = pendingValues[n]; delete pendingValues[n]; }
      clearError();
      send({ op: "set", values, moving: pendingMoving });
    }
    if (orbit.yaw || orbit.pitch) { send({ op: "orbit", yaw: orbit.yaw, pitch: orbit.pitch, moving: true }); }
    if (wTurn) { send({ op: "turn_w", degrees: wTurn, moving: true }); }
    if (zoom !== 1) { send({ op: "zoom", factor: zoom, moving: true }); }
    orbit = { yaw: 0, pitch: 0 }; wTurn = 0; zoom = 1;
  }

  function change(values, moving) {
    Object.assign(pendingValues, values);
    pendingMoving = moving;
    if (moving) queueFlush(); else flush();
  }

  function restSoon() {
    clearTimeout(restTimer);
    restTimer = setTimeout(() => { flush(); send({ op: "refine" }); }, 200);
  }

  // typing into a field: sent once the typing pauses (or at its change event, whichever is first)
  const typing = {};
  form.addEventListener("input", (ev) => {
    const t = ev.target;
    if (t.type === "range" && t.dataset.for) {
      const field = form.elements.namedItem(t.dataset.for);
      field.value = t.value;
      field.classList.remove("invalid");
      change({ [t.dataset.for]: t.value }, true);
    } else if (t.name && t.tagName === "INPUT") {
      clearTimeout(typing[t.name]);
      typing[t.name] = setTimeout(() => { delete typing[t.name]; commit(t); }, TYPING_PAUSE_MS);
    }
  });

  function commit(t) {
    t.classList.remove("invalid");
    const values = { [t.name]: t.value };
    if (t.name === "fractal.algebra") {
      fillFunctions(t.value);
      values["fractal.function"] = form.elements.namedItem("fractal.function").value;
    }
    const slider = form.querySelector(`input[type=range][data-for="${CSS.escape(t.name)}"]`);
    if (slider) slider.value = t.value;
    change(values, false);
  }

  form.addEventListener("change", (ev) => {
    const t = ev.target;
    if (t.type === "range" && t.dataset.for) { change({ [t.dataset.for]: t.value }, false); return; }
    if (!t.name) return;
    if (t.name in typing) { clearTimeout(typing[t.name]); delete typing[t.name]; }
    commit(t);
  });

  // ---------------------------------------------------------------- the camera by hand

  let drag = null;
  picture.addEventListener("contextmenu", (ev) => ev.preventDefault());
  picture.addEventListener("pointerdown", (ev) => {
    drag = { x: ev.clientX, y: ev.clientY, w: ev.shiftKey || ev.button === 2, x0: ev.clientX, y0: ev.clientY };
    picture.setPointerCapture(ev.pointerId);
    picture.classList.add("dragging");
    clearError();
  });
  picture.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    const dx = ev.clientX - drag.x, dy = ev.clientY - drag.y;
    drag.x = ev.clientX; drag.y = ev.clientY;
    if (drag.w) wTurn += dx * DEGREES_PER_PIXEL;
    else { orbit.yaw -= dx * DEGREES_PER_PIXEL; orbit.pitch += dy * DEGREES_PER_PIXEL; }
    queueFlush();
  });
  const endDrag = (ev) => {
    if (!drag) return;
    // a click (no drag): the path tracer's lens focuses on what the picture shows there
    const click = ev && ev.type === "pointerup" && !drag.w && Math.hypot(ev.clientX - drag.x0, ev.clientY - drag.y0) < 4;
    drag = null;
    picture.classList.remove("dragging");
    flush();
    if (click) {
      const r = view.getBoundingClientRect();
      const fx = (ev.clientX - r.left) / Math.max(1, r.width), fy = (ev.clientY - r.top) / Math.max(1, r.height);
      if (fx >= 0 && fx <= 1 && fy >= 0 && fy <= 1) { send({ op: "focus", x: fx, y: fy }); return; }
    }
    send({ op: "refine" });
  };
  picture.addEventListener("pointerup", endDrag);
  picture.addEventListener("pointercancel", endDrag);
  picture.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    zoom *= Math.pow(1.1, Math.max(-10, Math.min(10, ev.deltaY / 100)));
    queueFlush();
    restSoon();
  }, { passive: false });

  let lastTurn = 0;
  turn.addEventListener("input", () => {
    wTurn += Number(turn.value) - lastTurn;
    lastTurn = Number(turn.value);
    queueFlush();
  });
  turn.addEventListener("change", () => {
    turn.value = 0; lastTurn = 0;
    flush();
    send({ op: "refine" });
  });

  // ---------------------------------------------------------------- files

  const byId = (id) => document.getElementById(id);
  byId("save-scene").addEventListener("click", () => { clearError(); send({ op: "save_scene", name: byId("scene-name").value }); });
  byId("render-file").addEventListener("click", () => {
    clearError();
    progress.hidden = false; progress.value = 0;
    send({ op: "render_file", name: byId("image-name").value });
  });
  byId("add-keyframe").addEventListener("click", () => {
    clearError();
    send({ op: "keyframe", frames: Number(byId("keyframe-gap").value) });
  });
  byId("clear-keyframes").addEventListener("click", () => send({ op: "clear_keyframes" }));
  byId("frame").addEventListener("click", () => { clearError(); send({ op: "frame" }); });
  byId("save-animation").addEventListener("click", () => {
    clearError();
    send({ op: "save_animation", name: byId("animation-name").value, fps: Number(byId("animation-fps").value) });
  });

  connect();
})();
