// grainlab viewer: draws the snapshots of one run from the JSON in #grainlab-data.
// No network, no libraries: canvas 2D only.
(function () {
  "use strict";
  const D = JSON.parse(document.getElementById("grainlab-data").textContent);
  const TYPES = { f4: Float32Array, u1: Uint8Array, u2: Uint16Array, u4: Uint32Array };
  const FIELDS = {
    x: "f4", y: "f4", r: "f4", id: "u4", kind: "u1", lambda: "f4", contacts: "u1", dx: "f4",
    dy: "f4", rotation: "f4", strain: "f4", in_band: "u1", ci: D.index_dtype, cj: D.index_dtype, fn: "f4",
    porosity: "f4", chain: "u1", grain: "u4",
  };
  const MEMBRANE = 1;

  function decode(text, type) {
    const bin = atob(text);
    const bytes = new Uint8Array(bin.length);
    for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
    return new TYPES[type](bytes.buffer);
  }

  const snaps = D.snapshots.map(function (s) {
    const a = {};
    for (const key in FIELDS) a[key] = decode(s.arrays[key], FIELDS[key]);
    a.disp = new Float32Array(s.n);
    for (let i = 0; i < s.n; i++) a.disp[i] = Math.hypot(a.dx[i], a.dy[i]);
    // a shade per grain, spread by the golden ratio so that neighbouring labels differ
    a.grainShade = new Float32Array(s.n);
    for (let i = 0; i < s.n; i++) a.grainShade[i] = (a.grain[i] * 0.6180339887) % 1;
    // the pebbles of clumps (grains of more than one particle), outlined as one body
    const size = new Map();
    for (let i = 0; i < s.n; i++) size.set(a.grain[i], (size.get(a.grain[i]) || 0) + 1);
    a.pebbles = new Uint8Array(s.n);
    for (let i = 0; i < s.n; i++) a.pebbles[i] = Math.min(255, size.get(a.grain[i]));
    return { meta: s, a: a };
  });

  // ---------------------------------------------------------------- colour scales
  // sequential: dark blue - teal - yellow; diverging: blue - white - red
  const SEQ = [[48, 18, 59], [50, 100, 170], [30, 160, 150], [120, 200, 80], [250, 230, 40]];
  const DIV = [[40, 70, 160], [150, 180, 220], [245, 245, 245], [230, 150, 120], [170, 30, 40]];
  function ramp(stops, t) {
    if (!(t >= 0)) t = 0;
    if (t > 1) t = 1;
    const f = t * (stops.length - 1);
    const k = Math.min(Math.floor(f), stops.length - 2);
    const u = f - k;
    const c = stops[k].map(function (v, j) { return Math.round(v + u * (stops[k + 1][j] - v)); });
    return "rgb(" + c[0] + "," + c[1] + "," + c[2] + ")";
  }

  function percentile(key, q, absolute) {
    const values = [];
    snaps.forEach(function (s) {
      const a = s.a;
      for (let i = 0; i < s.meta.n; i++) {
        if (a.kind[i] === MEMBRANE) continue;
        const v = absolute ? Math.abs(a[key][i]) : a[key][i];
        if (isFinite(v)) values.push(v);
      }
    });
    if (!values.length) return 1;
    values.sort(function (p, q2) { return p - q2; });
    const v = values[Math.min(values.length - 1, Math.floor(q * values.length))];
    return v > 0 ? v : 1;
  }

  const MODES = {
    lambda: { label: "stability index \u03bb", key: "lambda", lo: 0, hi: 0.5, stops: SEQ },
    contacts: { label: "contacts", key: "contacts", lo: 0, hi: 6, stops: SEQ },
    displacement: { label: "displacement (m)", key: "disp", lo: 0, hi: percentile("disp", 0.98), stops: SEQ },
    rotation: { label: "rotation (rad)", key: "rotation", lo: -percentile("rotation", 0.98, true),
                hi: percentile("rotation", 0.98, true), stops: DIV },
    strain: { label: "local shear strain", key: "strain", lo: 0, hi: percentile("strain", 0.98), stops: SEQ },
    porosity: { label: "local porosity (power cell)", key: "porosity", lo: 0, hi: percentile("porosity", 0.98),
                stops: SEQ },
    chains: { label: "in a force chain (0 no, 1 yes)", key: "chain", lo: 0, hi: 1, stops: [[200, 200, 210], [150, 20, 30]] },
    grains: { label: "grain (one colour per rigid body)", key: "grainShade", lo: 0, hi: 1, stops: DIV },
  };

  // ---------------------------------------------------------------- elements
  const canvas = document.getElementById("grains");
  const ctx = canvas.getContext("2d");
  const curve = document.getElementById("curve");
  const cctx = curve.getContext("2d");
  const slider = document.getElementById("snapshot");
  const mode = document.getElementById("mode");
  const showContacts = document.getElementById("show-contacts");
  const showBand = document.getElementById("show-band");
  const showCracks = document.getElementById("show-cracks");
  // a cemented run's broken bonds: one segment each along the crack, blue in tension, red in shear
  const cracks = D.cracks ? {
    x: decode(D.cracks.x, "f4"), y: decode(D.cracks.y, "f4"), angle: decode(D.cracks.angle, "f4"),
    tension: decode(D.cracks.tension, "u1"), half: D.cracks.half_length_m,
  } : null;
  if (cracks) document.getElementById("cracks-control").hidden = false;
  const tip = document.getElementById("tip");
  const strainLabel = document.getElementById("strain-label");
  const legend = document.getElementById("legend");
  slider.max = String(snaps.length - 1);
  slider.value = String(snaps.length - 1);
  if (D.clumps) mode.value = "grains";  // a run with clumps opens on its bodies

  const lo = D.bounds[0], hi = D.bounds[1];
  const PAD = 12;
  const aspect = (hi[1] - lo[1]) / (hi[0] - lo[0]);
  canvas.width = 560;
  canvas.height = Math.max(200, Math.min(900, Math.round((canvas.width - 2 * PAD) * aspect + 2 * PAD)));
  const scale = Math.min((canvas.width - 2 * PAD) / (hi[0] - lo[0]), (canvas.height - 2 * PAD) / (hi[1] - lo[1]));
  function sx(x) { return PAD + (x - lo[0]) * scale; }
  function sy(y) { return canvas.height - PAD - (y - lo[1]) * scale; }

  let current = snaps.length - 1;
  let hovered = -1;

  function strainText(s) {
    return s.meta.axial_strain === null ? s.meta.name : (100 * s.meta.axial_strain).toFixed(2) + " %";
  }

  function drawBand(b) {
    if (!b) return;
    const t = [Math.cos(b.angle_deg * Math.PI / 180), Math.sin(b.angle_deg * Math.PI / 180)];
    const n = [-t[1], t[0]];
    const reach = 2 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1]);
    [-0.5, 0.5].forEach(function (side) {
      const c = [b.center[0] + side * b.thickness_m * n[0], b.center[1] + side * b.thickness_m * n[1]];
      ctx.beginPath();
      ctx.moveTo(sx(c[0] - reach * t[0]), sy(c[1] - reach * t[1]));
      ctx.lineTo(sx(c[0] + reach * t[0]), sy(c[1] + reach * t[1]));
      ctx.stroke();
    });
  }

  function draw() {
    const s = snaps[current], a = s.a, m = MODES[mode.value];
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    ctx.fillStyle = "#ffffff";
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    // a clump's outline: its pebbles stroked wide, then filled over, so that only the
    // boundary of their union stays dark
    ctx.strokeStyle = "#202020";
    ctx.lineWidth = 2.5;
    for (let i = 0; i < s.meta.n; i++) {
      if (a.pebbles[i] < 2) continue;
      ctx.beginPath();
      ctx.arc(sx(a.x[i]), sy(a.y[i]), Math.max(0.5, a.r[i] * scale), 0, 2 * Math.PI);
      ctx.stroke();
    }
    for (let i = 0; i < s.meta.n; i++) {
      ctx.beginPath();
      ctx.arc(sx(a.x[i]), sy(a.y[i]), Math.max(0.5, a.r[i] * scale), 0, 2 * Math.PI);
      if (a.kind[i] === MEMBRANE) {
        ctx.fillStyle = "#c8c8c8";
      } else {
        ctx.fillStyle = ramp(m.stops, (a[m.key][i] - m.lo) / (m.hi - m.lo));
      }
      ctx.fill();
    }
    if (showContacts.checked) {
      let fmax = 0;
      for (let k = 0; k < a.fn.length; k++) if (isFinite(a.fn[k])) fmax = Math.max(fmax, Math.abs(a.fn[k]));
      ctx.strokeStyle = "rgba(20,20,20,0.75)";
      for (let k = 0; k < a.ci.length; k++) {
        const i = a.ci[k], j = a.cj[k];
        const f = fmax > 0 && isFinite(a.fn[k]) ? Math.abs(a.fn[k]) / fmax : 0.3;
        ctx.lineWidth = 0.3 + 2.5 * f;
        ctx.beginPath();
        ctx.moveTo(sx(a.x[i]), sy(a.y[i]));
        ctx.lineTo(sx(a.x[j]), sy(a.y[j]));
        ctx.stroke();
      }
    }
    if (s.meta.walls) {
      ctx.strokeStyle = "#333333";
      ctx.lineWidth = 3;
      s.meta.walls.forEach(function (w) {
        ctx.beginPath();
        ctx.moveTo(sx(w[0][0]), sy(w[0][1]));
        ctx.lineTo(sx(w[1][0]), sy(w[1][1]));
        ctx.stroke();
      });
    }
    if (showBand.checked) {
      ctx.save();
      ctx.beginPath();
      ctx.rect(sx(lo[0]), sy(hi[1]), (hi[0] - lo[0]) * scale, (hi[1] - lo[1]) * scale);
      ctx.clip();
      ctx.lineWidth = 2;
      ctx.setLineDash([8, 5]);
      ctx.strokeStyle = "#d62728";
      drawBand(s.meta.band.first);
      ctx.strokeStyle = "#ff7f0e";
      drawBand(s.meta.band.second);
      ctx.restore();
    }
    if (cracks && showCracks.checked) {
      ctx.lineWidth = 2;
      for (let k = 0; k < s.meta.n_cracks; k++) {
        const dx = cracks.half * Math.cos(cracks.angle[k]), dy = cracks.half * Math.sin(cracks.angle[k]);
        ctx.strokeStyle = cracks.tension[k] ? "#1f77b4" : "#d62728";
        ctx.beginPath();
        ctx.moveTo(sx(cracks.x[k] - dx), sy(cracks.y[k] - dy));
        ctx.lineTo(sx(cracks.x[k] + dx), sy(cracks.y[k] + dy));
        ctx.stroke();
      }
    }
    if (hovered >= 0 && hovered < s.meta.n) {
      ctx.lineWidth = 2;
      ctx.strokeStyle = "#000000";
      ctx.beginPath();
      ctx.arc(sx(a.x[hovered]), sy(a.y[hovered]), a.r[hovered] * scale + 2, 0, 2 * Math.PI);
      ctx.stroke();
    }
    strainLabel.textContent = D.strain_label + " " + strainText(s) + " (" + s.meta.name + ", " + s.meta.n +
      " particles" + (s.meta.n_grains !== s.meta.n ? " in " + s.meta.n_grains + " grains" : "") + ", " +
      s.meta.n_contacts + " contacts drawn" + (cracks ? ", " + s.meta.n_cracks + " cracks so far" : "") + ")";
    legend.innerHTML = "";
    const bar = document.createElement("span");
    bar.className = "bar";
    bar.style.background = "linear-gradient(to right," + [0, 0.25, 0.5, 0.75, 1].map(function (t) {
      return ramp(m.stops, t);
    }).join(",") + ")";
    legend.append(m.label + ": " + fmt(m.lo) + " ", bar, " " + fmt(m.hi) + (m.key === "lambda" ? " and above" : ""));
    drawCurve();
  }

  function fmt(v) {
    if (v === 0) return "0";
    const a = Math.abs(v);
    return a >= 0.01 && a < 1000 ? v.toPrecision(3) : v.toExponential(2);
  }

  // ---------------------------------------------------------------- stress-strain curve
  const C = D.curve ? { xs: decode(D.curve.xs, "f4"), ys: decode(D.curve.ys, "f4") } : null;
  const CP = { left: 48, right: 10, top: 10, bottom: 34 };
  function curveBox() {
    let xmax = 0, ymin = Infinity, ymax = -Infinity;
    for (let k = 0; k < C.xs.length; k++) {
      xmax = Math.max(xmax, C.xs[k]);
      ymin = Math.min(ymin, C.ys[k]);
      ymax = Math.max(ymax, C.ys[k]);
    }
    snaps.forEach(function (s) { if (s.meta.axial_strain !== null) xmax = Math.max(xmax, s.meta.axial_strain); });
    if (!(ymax > ymin)) { ymin -= 1; ymax += 1; }
    return { xmax: xmax > 0 ? xmax : 1, ymin: Math.min(0, ymin), ymax: ymax };
  }
  function cx(x, b) { return CP.left + x / b.xmax * (curve.width - CP.left - CP.right); }
  function cy(y, b) { return curve.height - CP.bottom - (y - b.ymin) / (b.ymax - b.ymin) * (curve.height - CP.top - CP.bottom); }

  function drawCurve() {
    cctx.clearRect(0, 0, curve.width, curve.height);
    cctx.fillStyle = "#ffffff";
    cctx.fillRect(0, 0, curve.width, curve.height);
    if (!C) {
      cctx.fillStyle = "#555";
      cctx.fillText("no stress-strain record in this run", 20, 30);
      return;
    }
    const b = curveBox();
    cctx.strokeStyle = "#888";
    cctx.lineWidth = 1;
    cctx.strokeRect(CP.left, CP.top, curve.width - CP.left - CP.right, curve.height - CP.top - CP.bottom);
    cctx.fillStyle = "#333";
    cctx.font = "11px sans-serif";
    cctx.fillText(D.strain_label + " (%)", curve.width / 2 - 40, curve.height - 4);
    cctx.fillText(fmt(b.ymax), 2, CP.top + 8);
    cctx.fillText(fmt(b.ymin), 2, curve.height - CP.bottom);
    cctx.fillText("0", CP.left - 3, curve.height - CP.bottom + 13);
    cctx.fillText((100 * b.xmax).toFixed(1), curve.width - CP.right - 22, curve.height - CP.bottom + 13);
    cctx.save();
    cctx.translate(12, curve.height / 2 + 30);
    cctx.rotate(-Math.PI / 2);
    cctx.fillText(D.curve.y === "stress_ratio" ? "\u03c3\u2081/\u03c3\u2083" : D.curve.y === "friction_coefficient" ? "\u03bc = \u03c4/\u03c3\u2099" : D.curve.y, 0, 0);
    cctx.restore();
    cctx.strokeStyle = "#1f77b4";
    cctx.lineWidth = 1.5;
    cctx.beginPath();
    for (let k = 0; k < C.xs.length; k++) {
      if (k === 0) cctx.moveTo(cx(C.xs[k], b), cy(C.ys[k], b));
      else cctx.lineTo(cx(C.xs[k], b), cy(C.ys[k], b));
    }
    cctx.stroke();
    snaps.forEach(function (s, k) {
      const e = s.meta.axial_strain;
      if (e === null) return;
      const y = interpolate(e);
      cctx.fillStyle = k === current ? "#d62728" : "#999";
      cctx.beginPath();
      cctx.arc(cx(e, b), cy(y, b), k === current ? 5 : 3, 0, 2 * Math.PI);
      cctx.fill();
    });
    const e = snaps[current].meta.axial_strain;
    if (e !== null) {
      cctx.strokeStyle = "rgba(214,39,40,0.5)";
      cctx.beginPath();
      cctx.moveTo(cx(e, b), CP.top);
      cctx.lineTo(cx(e, b), curve.height - CP.bottom);
      cctx.stroke();
    }
  }

  function interpolate(e) {
    for (let k = 1; k < C.xs.length; k++) {
      if (C.xs[k] >= e) {
        const u = (e - C.xs[k - 1]) / ((C.xs[k] - C.xs[k - 1]) || 1);
        return C.ys[k - 1] + u * (C.ys[k] - C.ys[k - 1]);
      }
    }
    return C.ys[C.ys.length - 1];
  }

  curve.addEventListener("click", function (ev) {
    if (!C) return;
    const rect = curve.getBoundingClientRect();
    const b = curveBox();
    const e = (ev.clientX - rect.left - CP.left) / (curve.width - CP.left - CP.right) * b.xmax;
    let best = current, dist = Infinity;
    snaps.forEach(function (s, k) {
      if (s.meta.axial_strain !== null && Math.abs(s.meta.axial_strain - e) < dist) {
        dist = Math.abs(s.meta.axial_strain - e);
        best = k;
      }
    });
    show(best);
  });

  // ---------------------------------------------------------------- hover
  function grainAt(px, py) {
    const s = snaps[current], a = s.a;
    const x = lo[0] + (px - PAD) / scale, y = lo[1] + (canvas.height - PAD - py) / scale;
    let best = -1, bestD = Infinity;
    for (let i = 0; i < s.meta.n; i++) {
      const d = Math.hypot(a.x[i] - x, a.y[i] - y);
      if (d <= a.r[i] && d < bestD) { best = i; bestD = d; }
    }
    return best;
  }

  function describe(i) {
    const s = snaps[current], a = s.a;
    const rows = [
      ["particle id", String(a.id[i])],
      ["kind", a.kind[i] === MEMBRANE ? "membrane" : a.kind[i] === 2 ? "boundary grain" : "grain"],
      ["grain", String(a.grain[i]) + (a.pebbles[i] > 1 ? " (a clump of " + a.pebbles[i] + ")" : "")],
      ["\u03bb", a.lambda[i].toFixed(6)],
      ["contacts", String(a.contacts[i])],
      ["radius (m)", a.r[i].toExponential(3)],
      ["displacement (m)", a.disp[i].toExponential(3)],
      ["rotation (rad)", isFinite(a.rotation[i]) ? a.rotation[i].toExponential(3) : "n/a"],
      ["local shear strain", isFinite(a.strain[i]) ? a.strain[i].toFixed(4) : "n/a"],
      ["in shear band", ["no", "yes", "conjugate"][a.in_band[i]] || "no"],
      ["local porosity", isFinite(a.porosity[i]) ? a.porosity[i].toFixed(4) : "n/a"],
      ["in a force chain", a.chain[i] ? "yes" : "no"],
    ];
    return rows.map(function (r) {
      return "<tr><th>" + r[0] + "</th><td data-key=\"" + r[0] + "\">" + r[1] + "</td></tr>";
    }).join("");
  }

  canvas.addEventListener("mousemove", function (ev) {
    const rect = canvas.getBoundingClientRect();
    const px = (ev.clientX - rect.left) * canvas.width / rect.width;
    const py = (ev.clientY - rect.top) * canvas.height / rect.height;
    const i = grainAt(px, py);
    if (i !== hovered) { hovered = i; draw(); }
    if (i < 0) { tip.hidden = true; return; }
    tip.innerHTML = "<table>" + describe(i) + "</table>";
    tip.hidden = false;
    tip.style.left = (ev.pageX + 14) + "px";
    tip.style.top = (ev.pageY + 14) + "px";
  });
  canvas.addEventListener("mouseleave", function () { tip.hidden = true; hovered = -1; draw(); });

  // ---------------------------------------------------------------- controls
  function show(k) {
    current = Math.max(0, Math.min(snaps.length - 1, k));
    slider.value = String(current);
    hovered = -1;
    tip.hidden = true;
    draw();
  }
  slider.addEventListener("input", function () { show(Number(slider.value)); });
  [mode, showContacts, showBand, showCracks].forEach(function (el) { el.addEventListener("change", draw); });
  let timer = null;
  document.getElementById("play").addEventListener("click", function (ev) {
    if (timer) { clearInterval(timer); timer = null; ev.target.textContent = "\u25b6 play"; return; }
    ev.target.textContent = "\u25a0 stop";
    timer = setInterval(function () { show((current + 1) % snaps.length); }, 900);
  });
  document.getElementById("title").textContent = D.title;
  document.getElementById("source").textContent = D.source;

  // for scripts and tests: where a particle is drawn, in page (client) coordinates
  window.grainlabViewer = {
    snapshotCount: snaps.length,
    current: function () { return current; },
    show: show,
    clientPosition: function (i) {
      const rect = canvas.getBoundingClientRect();
      const a = snaps[current].a;
      return [rect.left + sx(a.x[i]) * rect.width / canvas.width, rect.top + sy(a.y[i]) * rect.height / canvas.height];
    },
  };
  draw();
})();
