/* pcbdyn: animated 3-D mode views (data from pcbdyn/report/view3d.py), drawn with plotly.js.
   Every element of class "view3d" holds a JSON payload, a plot, a mode picker, an amplitude slider and
   a pause button; its scenes move together as u(t) = a u_k cos(2 pi t / PERIOD). */
(function () {
  "use strict";
  var PERIOD = 1500;  // ms per cycle
  var FRAME = 60;     // ms between frames at least
  var STYLE = {part: "#1b7837", fixture: "#7b3294", mass: "#000000", "line mass": "#555555", stiffener: "#b35806",
               plate: "#777777", board: "#000000", region: "#555555", effect: "#d62728"};
  var NAMES = {part: "parts", fixture: "fixtures", mass: "masses", "line mass": "line masses", stiffener: "stiffeners",
               plate: "plates", board: "board outline", region: "regions", effect: "effects found"};
  var COOL = [[0, "#3b4cc0"], [0.25, "#8db0fe"], [0.5, "#dddddd"], [0.75, "#f4987a"], [1, "#b40426"]];

  function decode(b64, Type) {
    var bin = atob(b64), buf = new Uint8Array(bin.length);
    for (var i = 0; i < bin.length; i++) buf[i] = bin.charCodeAt(i);
    return new Type(buf.buffer);
  }

  function prepare(s) {
    var out = {title: s.title, xyz: decode(s.nodes, Float32Array), tris: decode(s.tris, Uint32Array),
               lines: decode(s.lines, Uint32Array), outlines: s.outlines, opacity: s.opacity,
               points: s.points ? decode(s.points, Float32Array) : null, pointLabels: s.point_labels || [],
               modes: s.modes.map(function (m) {
                 return {u: m.u ? decode(m.u, Int16Array) : null, s: m.s ? decode(m.s, Int8Array) : null,
                         p: m.p ? decode(m.p, Int16Array) : null};
               })};
    var lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    [out.xyz, out.points].forEach(function (a) {
      if (!a) return;
      for (var i = 0; i < a.length; i++) { var k = i % 3; lo[k] = Math.min(lo[k], a[i]); hi[k] = Math.max(hi[k], a[i]); }
    });
    out.lo = lo; out.hi = hi;
    out.span = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
    return out;
  }

  function moved(base, disp, f) {
    var n = base.length / 3, x = new Array(n), y = new Array(n), z = new Array(n);
    for (var i = 0; i < n; i++) {
      var d = disp ? f / 32767 : 0;
      x[i] = base[3 * i] + (d ? d * disp[3 * i] : 0);
      y[i] = base[3 * i + 1] + (d ? d * disp[3 * i + 1] : 0);
      z[i] = base[3 * i + 2] + (d ? d * disp[3 * i + 2] : 0);
    }
    return [x, y, z];
  }

  function traces(sc, k, phase, name, first) {
    var m = sc.modes[k], out = [], f = phase * sc.amp, P = moved(sc.xyz, m.u, f);
    if (sc.tris.length) {
      if (!sc.ijk) {
        sc.ijk = [[], [], []];
        for (var t = 0; t < sc.tris.length; t++) sc.ijk[t % 3].push(sc.tris[t]);
      }
      var inten = new Array(P[0].length);
      for (var q = 0; q < inten.length; q++) inten[q] = m.s ? m.s[q] / 127 * phase : 0;
      out.push({type: "mesh3d", scene: name, x: P[0], y: P[1], z: P[2], i: sc.ijk[0], j: sc.ijk[1], k: sc.ijk[2], intensity: inten,
                colorscale: COOL, cmin: -1, cmax: 1, opacity: sc.opacity, showscale: first, hoverinfo: "skip",
                flatshading: false, lighting: {ambient: 0.65, diffuse: 0.5, specular: 0.05},
                colorbar: {title: {text: sc.colour, side: "right"}, len: 0.6}});
    }
    if (sc.lines.length) {
      var lx = [], ly = [], lz = [];
      for (var b = 0; b < sc.lines.length; b += 2) {
        var a0 = sc.lines[b], a1 = sc.lines[b + 1];
        lx.push(P[0][a0], P[0][a1], null); ly.push(P[1][a0], P[1][a1], null); lz.push(P[2][a0], P[2][a1], null);
      }
      out.push({type: "scatter3d", mode: "lines", scene: name, x: lx, y: ly, z: lz, name: "beams (ribs)",
                line: {color: "#222222", width: 5}, hoverinfo: "skip", showlegend: first});
    }
    var groups = {}, listed = {};  // per kind, the single points (markers with their labels) apart from the lines
    sc.outlines.forEach(function (o) {
      var key = o.kind + (o.xyz.length > 1 ? "|lines" : "|points");
      (groups[key] = groups[key] || []).push(o);
    });
    Object.keys(groups).forEach(function (key) {
      var kind = key.split("|")[0], single = key.split("|")[1] === "points", xs = [], ys = [], zs = [], text = [];
      groups[key].forEach(function (o) {
        var pts = o.xyz.map(function (p, r) {
          var nd = o.node[r], d = m.u ? f / 32767 : 0;
          return [p[0] + d * (m.u ? m.u[3 * nd] : 0), p[1] + d * (m.u ? m.u[3 * nd + 1] : 0),
                  p[2] + d * (m.u ? m.u[3 * nd + 2] : 0)];
        });
        if (o.closed && pts.length > 2) pts.push(pts[0]);
        pts.forEach(function (p) { xs.push(p[0]); ys.push(p[1]); zs.push(p[2]); text.push(o.label); });
        if (!single) { xs.push(null); ys.push(null); zs.push(null); text.push(""); }
      });
      var colour = STYLE[kind] || "#555555";
      out.push({type: "scatter3d", scene: name, x: xs, y: ys, z: zs, text: text, name: NAMES[kind] || kind,
                legendgroup: kind, mode: single ? "markers+text" : "lines", textposition: "top center",
                marker: {size: 6, color: colour, symbol: "diamond"}, line: {color: colour, width: 4},
                hovertemplate: "%{text}<extra>" + kind + "</extra>", showlegend: first && !listed[kind]});
      listed[kind] = true;
    });
    if (sc.points) {
      var PP = moved(sc.points, m.p, f);
      out.push({type: "scatter3d", mode: "markers", scene: name, x: PP[0], y: PP[1], z: PP[2], text: sc.pointLabels,
                name: "test points", marker: {size: 4, color: "#d62728"}, showlegend: first,
                hovertemplate: "point %{text}<extra></extra>"});
    }
    return out;
  }

  function layout(scenes) {
    var lay = {margin: {l: 0, r: 0, t: 30, b: 0}, uirevision: "keep", showlegend: true,
               legend: {orientation: "h", x: 0, y: 0}, annotations: []};
    scenes.forEach(function (sc, i) {
      var pad = 0.25 * sc.span, name = i ? "scene" + (i + 1) : "scene", ranges = [], ratio = {};
      for (var a = 0; a < 3; a++) ranges.push([sc.lo[a] - pad, sc.hi[a] + pad]);
      var big = Math.max.apply(null, ranges.map(function (r) { return r[1] - r[0]; }));
      ["x", "y", "z"].forEach(function (ax, a) { ratio[ax] = (ranges[a][1] - ranges[a][0]) / big; });
      lay[name] = {domain: {x: [i / scenes.length, (i + 1) / scenes.length], y: [0.08, 1]},
                   xaxis: {range: ranges[0], title: {text: "x [mm]"}}, yaxis: {range: ranges[1], title: {text: "y [mm]"}},
                   zaxis: {range: ranges[2], title: {text: "z [mm]"}}, aspectmode: "manual", aspectratio: ratio,
                   camera: {eye: {x: 0.8, y: -0.95, z: 0.65}}};
      lay.annotations.push({text: sc.title, showarrow: false, x: (i + 0.5) / scenes.length, y: 1.0,
                            xref: "paper", yref: "paper", xanchor: "center", yanchor: "bottom"});
    });
    return lay;
  }

  function setup(root) {
    var data = JSON.parse(root.querySelector("script.view-data").textContent);
    var scenes = data.scenes.map(prepare), plot = root.querySelector(".plot");
    scenes.forEach(function (sc) { sc.colour = data.colour.replace(" (", "<br>("); });
    var pick = root.querySelector("select.mode"), slider = root.querySelector("input.amplitude");
    var button = root.querySelector("button.pause"), shown = root.querySelector("output.amplitude");
    data.labels.forEach(function (label, k) {
      var o = document.createElement("option"); o.value = k; o.textContent = label; pick.appendChild(o);
    });
    slider.value = data.amplitude;
    var state = {k: 0, running: true, busy: false, last: 0, t0: performance.now()};
    var lay = layout(scenes);
    root.dataset.frames = "0";

    function draw(now) {
      var phase = Math.cos(2 * Math.PI * (now - state.t0) / PERIOD), amp = parseFloat(slider.value), all = [];
      shown.textContent = (100 * amp).toFixed(0) + " %";
      scenes.forEach(function (sc, i) {
        sc.amp = amp * sc.span;
        all = all.concat(traces(sc, state.k, phase, i ? "scene" + (i + 1) : "scene", i === 0));
      });
      state.busy = true;
      root.dataset.phase = phase.toFixed(4);
      return Plotly.react(plot, all, lay, {displaylogo: false, responsive: true}).then(function () {
        state.busy = false;
        root.dataset.frames = String(parseInt(root.dataset.frames, 10) + 1);
      });
    }
    function tick(now) {
      if (state.running && state.visible && !state.busy && now - state.last >= FRAME) { state.last = now; draw(now); }
      requestAnimationFrame(tick);
    }
    state.visible = true;
    if (window.IntersectionObserver) {  // a view scrolled out of sight stops drawing (a page may hold several)
      new IntersectionObserver(function (seen) { state.visible = seen[0].isIntersecting; }).observe(plot);
    }
    pick.addEventListener("change", function () { state.k = parseInt(pick.value, 10); if (!state.running) draw(state.t0); });
    slider.addEventListener("input", function () { if (!state.running) draw(state.t0); });
    button.addEventListener("click", function () {
      state.running = !state.running; button.textContent = state.running ? "pause" : "play";
    });
    draw(state.t0).then(function () {
      if (scenes.length > 1) {  // turning one scene turns the others with it
        plot.on("plotly_relayout", function (e) {
          var turned = Object.keys(e).filter(function (k) { return /^scene\d*\.camera$/.test(k); })[0];
          if (!turned || state.syncing) return;
          var update = {};
          scenes.forEach(function (sc, i) {
            var name = (i ? "scene" + (i + 1) : "scene") + ".camera";
            if (name !== turned) update[name] = e[turned];
          });
          state.syncing = true;
          Plotly.relayout(plot, update).then(function () { state.syncing = false; });
        });
      }
      requestAnimationFrame(tick);
    });
  }

  function start() { document.querySelectorAll(".view3d").forEach(setup); }
  if (document.readyState === "loading") document.addEventListener("DOMContentLoaded", start); else start();
})();
