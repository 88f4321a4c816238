// pathbench history dashboard: draws every series of the inline JSON (report.py) as SVG.
// Written by hand, no library: the page must work offline and from file:// (CI's headless chromium).
// Every name from the data reaches the page as a text node or an attribute value (setAttribute),
// never as markup; links only from data.commit_url, which report.py checked to be http(s).
"use strict";
(function () {
  const data = JSON.parse(document.getElementById("history-data").textContent);
  const NS = "http://www.w3.org/2000/svg";
  const M = { l: 64, r: 36, t: 14, b: 58 };
  let W = 560, H = 230;  // a chart's size; the headline's are smaller, three to a row

  function el(tag, attrs, parent, ns) {
    const e = ns ? document.createElementNS(NS, tag) : document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    if (parent) parent.appendChild(e);
    return e;
  }
  function svg(tag, attrs, parent) { return el(tag, attrs, parent, true); }
  function text(parent, s) { parent.appendChild(document.createTextNode(s)); return parent; }
  // digits: significant digits, more when an axis spans a narrow range (ticks must differ).
  function fmt(v, digits) {
    if (v === null || v === undefined) return "–";
    const a = Math.abs(v), d = digits || 4;
    if (a >= 1e9) return (v / 1e9).toPrecision(d) + "G";
    if (a >= 1e6) return (v / 1e6).toPrecision(d) + "M";
    if (a >= 1e4) return (v / 1e3).toPrecision(d) + "k";
    return String(Number(v.toPrecision(d)));  // 9050, not 9.05e+3
  }
  function pct(v) { return v === null || v === undefined ? "–" : (v >= 0 ? "+" : "") + (100 * v).toFixed(2) + "%"; }
  const COMMIT_URL = /^https?:\/\//i.test(data.commit_url || "") ? data.commit_url : "";
  function commitNode(sha, parent) {
    const short = sha.slice(0, 10);
    if (COMMIT_URL) return text(el("a", { href: COMMIT_URL.split("{}").join(encodeURIComponent(sha)) }, parent), short);
    return text(el("code", { title: sha }, parent), short);
  }
  function median(xs) {
    const s = xs.slice().sort((a, b) => a - b), n = s.length;
    return n % 2 ? s[(n - 1) / 2] : s[n / 2 - 1] / 2 + s[n / 2] / 2;  // halves: no overflow
  }

  // A headline chart's series: line and dot colours are the classes c0..c5 of dashboard.css.
  const COLOURS = ["#1f4e79", "#b9770e", "#6c3483", "#117864", "#922b21", "#2e4053"];

  // One chart: x = runs in commit order, y = each repetition (dots) and the run's median (line).
  // list: one series, or several of one machine and device (the headline), one colour each, on
  // one commit axis (the union of their runs, in commit order).
  function chart(list, metric, parent, size) {
    if (!Array.isArray(list)) list = [list];
    [W, H] = size || [560, 230];
    const keyOf = (p) => p.date + " " + p.commit;
    const axis = new Map();
    for (const sr of list) for (const p of sr.points) if (!axis.has(keyOf(p))) axis.set(keyOf(p), p);
    const order = [...axis.keys()].sort();
    const slot = new Map(order.map((k, i) => [k, i]));
    const runs = order.map((k) => axis.get(k));
    const layers = list.map((sr) => ({ sr, pts: sr.points.map((p) => (metric === "rays" ? p.rays : p.values)),
      at: sr.points.map((p) => slot.get(keyOf(p))) }));
    // A loop, not Math.min(...all): a long series would overflow the argument list.
    let lo = Infinity, hi = -Infinity;
    for (const L of layers) for (const v of L.pts) for (const w of v) { if (w < lo) lo = w; if (w > hi) hi = w; }
    if (!(lo <= hi)) { lo = 0; hi = 1; }
    // Worked in units of the largest magnitude, so values near the double range cannot overflow.
    const scale = Math.max(Math.abs(lo), Math.abs(hi)) || 1;
    let nlo = lo / scale, nhi = hi / scale;
    if (nlo === nhi) { nlo -= Math.abs(nlo) * 0.01 || 1; nhi += Math.abs(nhi) * 0.01 || 1; }
    const pad = (nhi - nlo) * 0.08; nlo -= pad; nhi += pad;
    const n = runs.length;
    const x = (i) => M.l + (n === 1 ? 0.5 : i / (n - 1)) * (W - M.l - M.r);
    const yn = (nv) => M.t + (1 - (nv - nlo) / (nhi - nlo)) * (H - M.t - M.b);  // nv: in units of scale
    const y = (v) => yn(v / scale);
    const s = svg("svg", { width: W, height: H, viewBox: `0 0 ${W} ${H}`, class: "chart", "data-metric": metric });
    parent.appendChild(s);
    svg("line", { x1: M.l, y1: M.t, x2: M.l, y2: H - M.b, class: "axis" }, s);
    svg("line", { x1: M.l, y1: H - M.b, x2: W - M.r, y2: H - M.b, class: "axis" }, s);
    for (let k = 0; k <= 4; k++) {
      const nv = nlo + (k / 4) * (nhi - nlo), v = nv * scale;  // v: Infinity past the double range
      svg("line", { x1: M.l, x2: W - M.r, y1: yn(nv), y2: yn(nv), class: "grid" }, s);
      const digits = Math.min(8, Math.max(3, Math.ceil(Math.log10(Math.abs(nhi) / (nhi - nlo))) + 2));
      text(svg("text", { x: M.l - 4, y: yn(nv) + 3, class: "ytick" }, s), Number.isFinite(v) ? fmt(v, digits) : "");
    }
    const unit = metric === "rays" ? "rays/s" : list[0].unit;
    text(svg("text", { x: 12, y: M.t + (H - M.t - M.b) / 2, class: "ylabel",
      transform: `rotate(-90 12 ${M.t + (H - M.t - M.b) / 2})` }, s), unit);
    const step = Math.max(1, Math.ceil(n / 16));
    for (let i = 0; i < n; i += step) {
      text(svg("text", { x: x(i), y: H - M.b + 10, class: "xtick",
        transform: `rotate(55 ${x(i)} ${H - M.b + 10})` }, s), runs[i].commit.slice(0, 7));
    }
    let label = 0;
    layers.forEach((L, j) => {
      const colour = list.length > 1 ? COLOURS[j % COLOURS.length] : null;
      L.sr.changes.forEach((c) => {
        const a = L.at[c.index - 1], b = L.at[c.index];
        if (a === undefined || b === undefined) return;
        const cx = (x(a) + x(b)) / 2;
        // For rays/s a slower run is a drop, so the colour follows the time change either way.
        svg("line", { x1: cx, x2: cx, y1: M.t, y2: H - M.b, class: "cp " + (c.change > 0 ? "slower" : "faster") }, s);
        // Labels staggered over four lines so neighbouring change points stay readable.
        text(svg("text", { x: cx + 3, y: M.t + 9 + (label++ % 4) * 10, class: "cplabel" }, s),
          `${c.commit.slice(0, 7)} ${pct(c.change)}`);
      });
      let d = "";
      L.pts.forEach((v, i) => {
        if (v.length) d += (d ? " L" : "M") + x(L.at[i]).toFixed(1) + " " + y(median(v)).toFixed(1);
      });
      svg("path", { d: d, class: colour ? `median c${j % COLOURS.length}` : "median" }, s);
      L.pts.forEach((vals, i) => {
        const p = L.sr.points[i];
        for (const v of vals) {
          const c = svg("circle", { cx: x(L.at[i]), cy: y(v), r: 2.2, class: colour ? `rep c${j % COLOURS.length}` : "rep" }, s);
          text(svg("title", {}, c), `${p.commit.slice(0, 12)} ${p.date}\n${p.subject}\n${fmt(v)} ${unit}`);
        }
      });
    });
    return s;
  }

  // The parts of the names that differ within a group ("pixel", "wavefront"): the legend.
  function distinct(names) {
    const parts = names.map((nm) => nm.split("/"));
    const same = (k) => parts.every((p) => p[k] === parts[0][k]);
    return parts.map((p) => p.filter((_, k) => !same(k)).join("/") || p.join("/"));
  }

  function summary() {
    const t = document.getElementById("summary");
    const head = el("tr", {}, t);
    for (const h of ["machine", "preset", "benchmark", "runs", "baseline", "latest", "latest vs baseline",
      "last change", "at commit", "latest vs before it"]) text(el("th", {}, head), h);
    for (const s of data.series) {
      const r = el("tr", {}, t);
      text(el("td", { title: s.machine_id }, r), s.machine + " " + s.machine_id.slice(0, 6));
      text(el("td", {}, r), s.preset || "–");
      text(el("a", { href: "#" + s.id }, el("td", {}, r)), s.benchmark);
      text(el("td", {}, r), String(s.points.length));
      text(el("td", {}, r), fmt(s.baseline) + " " + s.unit);
      text(el("td", {}, r), fmt(s.latest) + " " + s.unit);
      text(el("td", { class: s.latest_vs_baseline > 0 ? "slower" : "faster" }, r), pct(s.latest_vs_baseline));
      const last = s.changes[s.changes.length - 1];
      text(el("td", {}, r), last ? pct(last.change) : "none");
      const at = el("td", {}, r);
      if (last) commitNode(last.commit, at);
      text(el("td", {}, r), pct(s.latest_vs_before_last_change));
    }
  }

  function panel(s, parent, id) {
    const p = el("div", { class: "panel", id: id }, parent);
    const cap = el("p", { class: "caption" }, p);
    text(el("b", {}, cap), `${s.device ? s.device.toUpperCase() + " · " : ""}${s.machine} ${s.machine_id.slice(0, 6)}`);
    text(cap, `${s.preset ? " · preset " + s.preset : ""} · ${s.points.length} runs · latest ${fmt(s.latest)} ` +
      `${s.unit} (${pct(s.latest_vs_baseline)} vs first)`);
    for (const c of s.changes) {
      text(cap, ` · change ${pct(c.change)} ${c.p_value === null ? "(exact)" : "p=" + c.p_value.toExponential(1)} at `);
      commitNode(c.commit, cap);
    }
    return p;
  }

  // The first screen: the paper frame and the suite, one chart per machine and device, its
  // strategies (or workloads) as coloured lines over commits, change points marked.
  function headline() {
    const root = document.getElementById("headline");
    const chosen = data.series.filter((s) => s.headline);
    if (!chosen.length) return;
    const labels = [...new Set(chosen.map((s) => s.headline))];
    for (const label of labels) {
      const groups = new Map();
      for (const s of chosen.filter((c) => c.headline === label)) {
        const key = s.machine_id + " " + s.device + " " + s.unit;
        if (!groups.has(key)) groups.set(key, []);
        groups.get(key).push(s);
      }
      text(el("h2", {}, root), label);
      const row = el("div", { class: "row headline" }, root);
      for (const list of [...groups.values()].sort((a, b) => (a[0].machine + a[0].device < b[0].machine + b[0].device ? -1 : 1))) {
        list.sort((a, b) => (a.benchmark < b.benchmark ? -1 : 1));
        const s0 = list[0];
        const p = el("div", { class: "panel", id: "h-" + s0.id }, row);
        const cap = el("p", { class: "caption" }, p);
        text(el("b", {}, cap), `${s0.device ? s0.device.toUpperCase() + " · " : ""}${s0.machine} ${s0.machine_id.slice(0, 6)}`);
        text(cap, ` · ${Math.max(...list.map((s) => s.points.length))} runs`);
        const legend = el("p", { class: "caption legend" }, p);
        distinct(list.map((s) => s.benchmark)).forEach((name, j) => {
          const item = el("a", { href: "#" + list[j].id, title: list[j].benchmark }, legend);
          const sw = svg("svg", { width: 10, height: 10, class: "swatch" }, item);
          svg("rect", { width: 10, height: 10, fill: list.length > 1 ? COLOURS[j % COLOURS.length] : "#1f4e79" }, sw);
          text(item, ` ${name}: ${fmt(list[j].latest)} ${list[j].unit} (${pct(list[j].latest_vs_baseline)} vs first)`);
          text(legend, " ");
        });
        chart(list, "time", p, [440, 220]);
      }
    }
  }

  // One row per benchmark: its series on every machine side by side, CPU before GPU, so a CPU and
  // a GPU run of the same render (or two machines) can be read against each other.
  function plots() {
    const root = document.getElementById("plots");
    const groups = new Map();
    for (const s of data.series) {
      if (!groups.has(s.group)) groups.set(s.group, []);
      groups.get(s.group).push(s);
    }
    for (const [group, list] of groups) {
      const row = el("div", { class: "row" }, root);
      const devices = [...new Set(list.map((s) => s.device).filter(Boolean))].join(" | ");
      text(el("h3", {}, row), group.split("{device}").join(devices.includes("|") ? "[" + devices + "]" : devices || "-"));
      list.sort((a, b) => (a.device + a.machine + a.preset < b.device + b.machine + b.preset ? -1 : 1));
      for (const s of list) {
        const p = panel(s, row, s.id);
        chart(s, "time", p);
        if (s.points.some((q) => q.rays.length)) chart(s, "rays", p);
      }
    }
  }

  headline();
  summary();
  plots();
  document.body.setAttribute("data-headline", String(document.querySelectorAll("#headline svg.chart").length));
  document.body.setAttribute("data-drawn", String(document.querySelectorAll("#plots svg.chart").length));
})();
