"""The suite's one page: HTML (self-contained: inline CSS, no script, so it shows anywhere and
cannot raise a console error) and the same content as Markdown."""
from __future__ import annotations

import html

CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Roboto,sans-serif;margin:2em auto;max-width:1300px;color:#222;padding:0 1em}
h1{font-size:1.5em;margin-bottom:.2em}h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ddd}
.facts{color:#555;font-size:.9em}.facts b{color:#222}
table{border-collapse:collapse;font-size:.86em;margin:.6em 0;width:100%}
th,td{border:1px solid #ddd;padding:.3em .5em;text-align:right;white-space:nowrap}
th{background:#f4f4f4}td.l,th.l{text-align:left}table.wl td{white-space:normal}tr:nth-child(even) td{background:#fafafa}
.faster{color:#1a7f37;font-weight:600}.slower{color:#c62828;font-weight:600}.same{color:#555}
.warn{color:#b26a00;font-weight:600}.skip{color:#888}.mono{font-family:ui-monospace,monospace;font-size:.95em}
.verdict{display:inline-block;margin:.3em .8em .3em 0;padding:.35em .7em;border-radius:4px;background:#f0f3f6}
.bar{display:inline-block;height:.7em;background:#4a78c2;vertical-align:middle;margin-right:.4em}
"""


def _num(v, digits=3, scale=1.0):
    if v is None:
        return "–"
    x = v * scale
    if x == 0:
        return "0"
    if abs(x) >= 1000:
        return f"{x:,.0f}"
    return f"{x:.{digits}g}"


def _mb(v):
    return "–" if not v else f"{v / 2**20:,.0f}"


def _cells(r: dict, ref_names: list[str], reps: int = 9) -> list[tuple[str, str, str]]:
    """(text, css class, title) per column of a row that ran."""
    prev = r.get("previous") or {}
    if prev.get("verdict") in ("faster", "slower", "same"):
        vs_prev = (f"{prev['verdict']} {prev['change'] * 100:+.1f}%", prev["verdict"],
                   f"p={prev['p']:.2g}, was {prev['before_ms']:.4g} ms ({prev.get('run_date', '')})")
    else:
        vs_prev = ("no earlier run", "same", "")
    energy = _num(r.get("joules_per_frame"), 3)
    energy_title = r.get("energy_reason") or (f"busy fraction {r['energy_busy_fraction']:.2f} of the window"
                                              if r.get("energy_busy_fraction") is not None else "")
    if r.get("joules_per_frame") is None:
        energy = "n/a"
    elif (r.get("energy_busy_fraction") or 1) < 0.5:  # the window was mostly work between frames
        energy += f" ({r['energy_busy_fraction'] * 100:.0f}% frame)"
    if r.get("throttled") is None:
        clocks = ("–", "", "")
    else:
        state = "THROTTLED" if r["throttled"] else "ok"
        clocks = (f"{_num(r.get('sm_clock_mhz'), 4)} MHz, {_num(r.get('temperature_c_max'), 3)} °C, {state}",
                  "warn" if r["throttled"] else "", f"clock-event reasons 0x{r.get('throttle_reasons') or 0:x}")
    n = r.get("repetitions") or reps
    cells = [(_num(r.get("ms"), 4) + (f" (n={n})" if n < reps else ""), "", f"median of {n} repetitions"),
             (_num(r.get("rays_per_second"), 4, 1e-6), "", ""),
             (_num(r.get("samples_per_second"), 4, 1e-6), "", ""),
             (f"{_mb(r.get('peak_host_bytes'))} / {_mb(r.get('peak_device_bytes'))}", "", "host / device MiB"),
             (_num(r.get("build_seconds"), 3), "", "the scene's acceleration structure, built once per benchmark "
              "(not in the frame time or the energy)"),
             (energy, "" if r.get("joules_per_frame") is not None else "skip", energy_title),
             (_num(r.get("rays_per_joule"), 4, 1e-6), "", ""), clocks,
             ((r.get("film_hash") or "–").replace("fnv1a64:", ""), "mono", r.get("film_hash") or ""), vs_prev]
    for name in ref_names:
        ref = (r.get("references") or {}).get(name)
        if ref and ref.get("ms") and r.get("ms"):
            speed = ref["ms"] / r["ms"]
            cells.append((f"{ref['ms']:.4g} ms ({speed:.2f}x)", "", f"this machine is {speed:.2f}x as fast; "
                          f"reference run {ref.get('run_date', '')}"))
        else:
            cells.append(("–", "skip", ""))
    return cells


HEAD = ["workload", "device", "ms / frame", "Mrays/s", "Msamples/s", "peak MiB", "build s", "J / frame", "Mrays / J",
        "SM clock, temp, throttle", "film hash", "vs previous run"]


def _summary(s: dict) -> list[str]:
    rows = [r for r in s["rows"] if r["status"] == "ok"]
    count = {k: sum(1 for r in rows if (r.get("previous") or {}).get("verdict") == k) for k in ("faster", "slower", "same")}
    out = [f"{len(rows)} measured", f"{sum(1 for r in s['rows'] if r['status'] != 'ok')} skipped"]
    if any(r.get("previous") for r in rows):
        out += [f"{count['faster']} faster", f"{count['slower']} slower", f"{count['same']} same as the previous run"]
    th = sum(1 for r in rows if r.get("throttled"))
    if th:
        out.append(f"{th} THROTTLED")
    return out


def write_html(path: str, s: dict) -> None:
    e = html.escape
    refs = s.get("reference_machines", [])
    h = ["<!DOCTYPE html>", '<html lang="en"><head><meta charset="utf-8">',
         '<meta name="viewport" content="width=device-width, initial-scale=1">',
         f"<title>pathbench suite v{s['version']} — {e(s['machine']['name'])}</title>", f"<style>{CSS}</style></head><body>",
         f"<h1>pathbench suite v{s['version']} ({e(s['mode'])}) on {e(s['machine']['name'])}</h1>",
         '<p class="facts">' + " · ".join(f"<b>{e(k)}</b> {e(str(v))}" for k, v in s["facts"]) + "</p>",
         "<div>" + "".join(f'<span class="verdict">{e(x)}</span>' for x in _summary(s)) + "</div>",
         "<h2>Per workload and device</h2><table><thead><tr>"]
    h += [f'<th class="{"l" if i < 2 else ""}">{e(c)}</th>' for i, c in enumerate(HEAD)]
    h += [f"<th>{e(n)}</th>" for n in refs]
    h.append("</tr></thead><tbody>")
    best = max([r.get("rays_per_second") or 0 for r in s["rows"]] + [1])
    for r in s["rows"]:
        h.append(f'<tr><td class="l">{e(r["workload"])}</td><td class="l">{e(r["device"])}'
                 f'{(" <span class=mono>" + e(r["isa"]) + "</span>") if r.get("isa") else ""}</td>')
        if r["status"] != "ok":
            h.append(f'<td class="l skip" colspan="{len(HEAD) - 2 + len(refs)}">skipped: {e(r.get("reason", ""))}</td></tr>')
            continue
        for i, (text, cls, title) in enumerate(_cells(r, refs, s.get("repetitions", 9))):
            bar = ""
            if i == 1 and r.get("rays_per_second"):
                bar = f'<span class="bar" style="width:{max(1, int(60 * r["rays_per_second"] / best))}px"></span>'
            h.append(f'<td class="{e(cls)}" title="{e(title)}">{bar}{e(text)}</td>')
        h.append("</tr>")
    h.append("</tbody></table>")
    h.append("<p class=facts>Times are the median over the repetitions (compare's U test needs ≥ 9; n= marks a "
             "row with fewer). The scene's acceleration structure is built once per benchmark (build s) and "
             "neither its time nor its energy is in the frame's. Energy: NVML on GPUs, RAPL on CPUs where "
             "readable, over each repetition's frames (hover for the busy fraction: the frames' share of the "
             "window); n/a with the reason where the counter cannot be read. "
             "vs previous: this machine's latest earlier run in the history database, judged as "
             "<code>pathbench compare</code> does (Mann-Whitney U, p &lt; 0.05 and more than 5 %). Reference "
             "columns: that machine's median time and how many times as fast this machine is.</p>")
    notes = [(r["workload"], r["device"], r["energy_reason"]) for r in s["rows"] if r.get("energy_reason")]
    if notes:
        h.append("<h2>Energy not measured</h2><ul>")
        seen = set()
        for w, d, why in notes:
            if (d, why) in seen:
                continue
            seen.add((d, why))
            h.append(f"<li><b>{e(d)}</b>: {e(why)}</li>")
        h.append("</ul>")
    h.append("<h2>Workloads</h2><table class=wl><thead><tr>" + "".join(
        f'<th class="l">{c}</th>' for c in ("workload", "stresses", "triangles", "instanced", "materials", "size", "licence"))
        + "</tr></thead><tbody>")
    for w in s["workloads"]:
        st = w["run_settings"]
        size = f"{st['width']}x{st['height']}, {st['spp']} spp, {st.get('bounces', 2)} bounces, {st.get('sampling', 'nee')}"
        h.append("<tr>" + "".join(f'<td class="l">{e(str(x))}</td>' for x in (
            w["name"], w["stresses"], f"{w['triangles']:,}", f"{w['instanced_triangles']:,}", ", ".join(w["materials"]),
            size, w["licence"])) + "</tr>")
    h.append("</tbody></table>")
    h.append(f"<p class=facts>Written by <code>{e(s['command'])}</code>. Bench JSON beside this page; "
             f"records in {e(s['db'] or 'no database (--no-record)')}.</p></body></html>")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(h) + "\n")


def _md(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def write_markdown(path: str, s: dict) -> None:
    refs = s.get("reference_machines", [])
    m = [f"# pathbench suite v{s['version']} ({s['mode']}) on {_md(s['machine']['name'])}", "",
         " · ".join(f"**{_md(k)}** {_md(v)}" for k, v in s["facts"]), "", "**" + ", ".join(_summary(s)) + "**", "",
         "| " + " | ".join(HEAD + refs) + " |", "|" + "|".join(["---"] * (len(HEAD) + len(refs))) + "|"]
    for r in s["rows"]:
        dev = r["device"] + (f" ({r['isa']})" if r.get("isa") else "")
        if r["status"] != "ok":
            m.append(f"| {_md(r['workload'])} | {_md(dev)} | skipped: {_md(r.get('reason', ''))} |" + " |" * (len(HEAD) - 3 + len(refs)))
            continue
        m.append(f"| {_md(r['workload'])} | {_md(dev)} | " +
                 " | ".join(_md(c[0]) for c in _cells(r, refs, s.get("repetitions", 9))) + " |")
    notes = sorted({(r["device"], r["energy_reason"]) for r in s["rows"] if r.get("energy_reason")})
    if notes:
        m += ["", "Energy not measured:"] + [f"- {_md(d)}: {_md(why)}" for d, why in notes]
    m += ["", "| workload | stresses | triangles | instanced | materials | licence |", "|---|---|---|---|---|---|"]
    for w in s["workloads"]:
        m.append(f"| {_md(w['name'])} | {_md(w['stresses'])} | {w['triangles']:,} | {w['instanced_triangles']:,} | "
                 f"{_md(', '.join(w['materials']))} | {_md(w['licence'])} |")
    m += ["", f"Written by `{s['command']}`."]
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(m) + "\n")
