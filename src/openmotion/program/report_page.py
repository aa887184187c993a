"""The run report's page around its figures (report_html.py): options and summary on top,
the extents table, the figures, the event table and the program listing.

The listing is linked to the path both ways: a click on a listing line (or on an event)
draws that line's stretch over the path and marks the line; a click on the path marks the
line it belongs to in the listing. The page is one file that works offline: plotly.js is
embedded, compressed (plotly_embed.py), and the listing script runs once the figures are
drawn.
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from .report import RunSummary
    from .runner import ProgramRunner

#: Listing lines shown at most (a longer program lists its first lines and says so).
MAX_LISTING_LINES = 20_000
#: Event table rows shown at most.
MAX_EVENTS = 2000

PATH_DIV = "om-path"

_STYLE = ("body{font-family:system-ui,sans-serif;margin:1.5em auto;max-width:1200px}"
          "table{border-collapse:collapse}td,th{border:1px solid #ccc;padding:2px 8px;"
          "text-align:left}pre{background:#f6f6f6;padding:.8em}h2{margin-top:1.5em}"
          "#listing{max-height:28em;overflow:auto;border:1px solid #ccc}"
          "#listing table td{border:none;padding:0 8px;font-family:monospace;"
          "white-space:pre}#listing td.n{color:#888;text-align:right}"
          "tr[data-line]{cursor:pointer}tr.moves td.n{color:#333}"
          "tr.sel{background:#fde0f0}td.num{text-align:right}")

# A click on a listing line or event: its stretch drawn on the path ("selected line"
# trace), the line marked; a click on the path: its line marked in the listing.
_SCRIPT = """
(async function () {
  const gd = document.getElementById(%(div)s);
  let marked = null;
  if (document.getElementById('listing-data')) {
    // one row per source line: <tr id=L<n> data-line=<n> [class=moves]>
    const {lines, moves} = JSON.parse(await window.openmotionInflate('listing-data'));
    const moving = new Uint8Array(lines.length + 2);
    for (const [a, b] of moves) for (let n = a; n <= b; n++) moving[n] = 1;
    const table = document.querySelector('#listing table');
    const frag = document.createDocumentFragment();
    lines.forEach((text, k) => {
      const n = k + 1, tr = document.createElement('tr');
      tr.id = 'L' + n; tr.dataset.line = n; if (moving[n]) tr.className = 'moves';
      const num = document.createElement('td'), src = document.createElement('td');
      num.className = 'n'; num.textContent = n; src.textContent = text;
      tr.append(num, src); frag.append(tr);
    });
    table.append(frag);
  }
  const TYPES = {f4: Float32Array, f8: Float64Array, i4: Int32Array, i2: Int16Array,
                 u1: Uint8Array, i1: Int8Array, u2: Uint16Array, u4: Uint32Array};
  function arr(v) {  // plotly keeps binary arrays as {dtype, bdata} in gd.data
    if (!v || !v.bdata) return v || [];
    const raw = atob(v.bdata), bytes = new Uint8Array(raw.length);
    for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
    return new TYPES[v.dtype](bytes.buffer);
  }
  function mark(n) {
    if (marked) marked.classList.remove('sel');
    marked = document.getElementById('L' + n);
    if (marked) { marked.classList.add('sel'); marked.scrollIntoView({block: 'nearest'}); }
  }
  function pick(n) {
    mark(n);
    if (!gd || !gd.data) return;
    const sel = gd.data.findIndex(d => d.name === 'selected line');
    const three = gd.data[0].type === 'scatter3d';
    const xs = [], ys = [], zs = [];
    for (const d of gd.data) {
      if (d.name !== 'rapid' && d.name !== 'feed') continue;
      const c = arr(d.customdata), x = arr(d.x), y = arr(d.y), z = arr(d.z);
      let last = -2;
      for (let i = 0; i < c.length; i++) {
        if (c[i] !== n || Number.isNaN(x[i])) continue;
        if (i !== last + 1 && xs.length) { xs.push(NaN); ys.push(NaN); zs.push(NaN); }
        xs.push(x[i]); ys.push(y[i]); if (three) zs.push(z[i]);
        last = i;
      }
    }
    const upd = three ? {x: [xs], y: [ys], z: [zs]} : {x: [xs], y: [ys]};
    if (sel >= 0) Plotly.restyle(gd, upd, [sel]);
    window.openmotionSelected = {line: n, points: xs.filter(x => !Number.isNaN(x)).length};
  }
  window.openmotionPick = pick;
  document.querySelectorAll('tr[data-line]').forEach(
    tr => tr.addEventListener('click', () => pick(Number(tr.dataset.line))));
  if (gd && gd.on) gd.on('plotly_click', ev => {
    const p = ev.points && ev.points[0];
    if (p && p.customdata !== undefined) pick(Number(p.customdata));
  });
})();
"""


def extents(run: ProgramRunner, pos: np.ndarray, cutting: np.ndarray, off: np.ndarray,
            lims: list[tuple[float, float] | None],
            scale: np.ndarray | None = None) -> list[tuple[str, ...]]:
    """Per moving axis: letter, lowest and highest position of the cuts (feed moves), of
    all motion (rapids too), and the soft limits, as text in the drawn frame (minus `off`,
    times `scale` per axis: report_html.drawn_units)."""
    def num(x: float) -> str:
        return f"{x:.4f}" if math.isfinite(x) else ("-inf" if x < 0 else "inf")

    f = np.ones(len(run.letters)) if scale is None else np.asarray(scale, dtype=float)
    rows = []
    for k, letter in enumerate(run.letters):
        if np.ptp(pos[:, k]) <= 1e-9:
            continue
        p = (pos[:, k] - off[k]) * f[k]
        c = p[cutting] if cutting.any() else p[:0]
        cut = (num(c.min()), num(c.max())) if c.size else ("-", "-")
        lim = lims[k]
        soft = ("-", "-") if lim is None else (num((lim[0] - off[k]) * f[k]),
                                               num((lim[1] - off[k]) * f[k]))
        rows.append((letter, *cut, num(p.min()), num(p.max()), *soft))
    return rows


def _extents_table(rows: list[tuple[str, ...]], frame: str, units: str) -> str:
    body = "".join("<tr>" + f"<td>{html.escape(r[0])}</td>" + "".join(
        f"<td class=num>{x}</td>" for x in r[1:]) + "</tr>" for r in rows)
    return (f"<h2>Extents ({html.escape(frame)} coordinates, {units} or deg)</h2>"
            "<table id=extents><tr><th>axis</th><th>cuts lowest</th><th>cuts highest</th>"
            "<th>all motion lowest</th><th>all motion highest</th><th>soft limit low</th>"
            f"<th>soft limit high</th></tr>{body}</table>")


def _events_table(run: ProgramRunner) -> str:
    rows = [f"<tr data-line={e.line}><td>{e.t - run.t_start:.4f}</td>"
            f"<td>{html.escape(e.kind)}</td><td>{e.line}</td><td>{html.escape(e.text)}</td></tr>"
            for e in run.events[:MAX_EVENTS]]
    if len(run.events) > MAX_EVENTS:
        rows.append(f"<tr><td colspan=4>... {len(run.events) - MAX_EVENTS} more</td></tr>")
    return ("<h2>Events</h2><table><tr><th>t (s)</th><th>kind</th><th>line</th>"
            f"<th>what</th></tr>{''.join(rows)}</table>")


def listing_data(run: ProgramRunner, text: str) -> dict[str, list]:
    """The listing as the page's script builds it: the source lines (at most
    MAX_LISTING_LINES) and the motion lines as [first, last] runs of line numbers."""
    moving = sorted({o.line for o in run.ops if o.kind in ("line", "arc")})
    lines = text.splitlines()[:MAX_LISTING_LINES]
    runs: list[list[int]] = []
    for n in moving:
        if n > len(lines):
            break
        if runs and runs[-1][1] == n - 1:
            runs[-1][1] = n
        else:
            runs.append([n, n])
    return {"lines": lines, "moves": runs}


def _listing(run: ProgramRunner, text: str) -> str:
    """The listing's place and its data (JSON, gzip + base64: G-code packs about 4 to 1;
    the script makes one row per line: markup per row written out here was 1.8 of the
    2.8 MB of a 100k-line program's page)."""
    from .plotly_embed import gzip_b64

    n = len(text.splitlines())
    more = (f"<p>... {n - MAX_LISTING_LINES} more lines not listed</p>"
            if n > MAX_LISTING_LINES else "")
    data = gzip_b64(json.dumps(listing_data(run, text), separators=(",", ":")))
    return ("<h2>Program</h2><p>Click a line to see its stretch on the path; click the path "
            "to find its line.</p><div id=listing><table></table></div>"
            f"<script type=application/gzip id=listing-data>{data}</script>{more}")


def program_text(run: ProgramRunner) -> str | None:
    """The program's source for the listing: the G-code file the runner read (a point
    table's lines are its generated G-code, not the file, so it has none)."""
    f = Path(run.file) if run.file else None
    if f is None or f.suffix.lower() in (".toml", ".csv") or not f.is_file():
        return None
    return f.read_text(encoding="utf-8", errors="replace")


def units_note(run: ProgramRunner, units: str) -> str:
    """The page's line on the units it draws in (the program's, `drawn_units`)."""
    pu = run.program_units
    code = "G20" if pu.units == "inch" else "G21"
    text = (f"Figures and extents are in the program's units ({units}, {code}); feeds and "
            f"speeds in {units}/min.")
    if pu.switched:
        text += (" The program changes units after its first motion: drawn in the units in "
                 "force at its first motion.")
    machine = "in" if run.machine_units == "inch" else "mm"
    if machine != units:
        text += f" The summary above is in machine units ({machine})."
    return text


def write_page(run: ProgramRunner, summary: RunSummary, summary_text: str, err: np.ndarray,
               path: Path, options: str = "", origin: np.ndarray | None = None) -> Path:
    """Write the page (one file: plotly.js embedded, plotly_embed.py) to `path`; its path."""
    from .plotly_embed import after_drawing, figure_html, head_scripts
    from .report_html import _figures, drawn_units, soft_limits

    del summary  # the text holds it; kept in the signature for callers that format apart
    title = html.escape(run.file or "program")
    frame = "machine" if origin is None else "program"
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>openmotion run: "
             f"{title}</title>{head_scripts()}<style>{_STYLE}</style>"
             f"</head><body><h1>openmotion run: {title}</h1>"]
    if options:
        parts.append(f"<p>{html.escape(options)}</p>")
    parts.append(f"<pre>{html.escape(summary_text)}</pre>")
    units, scale = drawn_units(run)
    parts.append(f"<p id=units>{html.escape(units_note(run, units))}</p>")
    _, idx, pos = run.trace()
    if len(pos):
        off = np.zeros(pos.shape[1]) if origin is None else np.asarray(origin, dtype=float)
        ops = [run.op_of.get(int(i)) for i in idx]
        cutting = np.array([o is not None and not o.rapid and o.kind in ("line", "arc")
                            for o in ops], dtype=bool)
        rows = extents(run, pos, cutting, off, soft_limits(run), scale)
        if rows:
            parts.append(_extents_table(rows, frame, units))
    for k, (heading, fig) in enumerate(_figures(run, err, origin)):
        parts.append(f"<h2>{html.escape(heading)}</h2>")
        parts.append(figure_html(fig, PATH_DIV if heading == "Path" else f"om-fig{k}"))
    parts.append(_events_table(run))
    text = program_text(run)
    if text is not None:
        parts.append(_listing(run, text))
    parts.append(after_drawing(_SCRIPT % {'div': json.dumps(PATH_DIV)}) + "</body></html>")
    path.write_text("\n".join(parts), encoding="utf-8")
    return path
