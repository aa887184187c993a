"""The run report's page around its figures (report_html.py): options and summary on top,
the extents table, the figures, the event table and the program listing.

The listing is linked to the path both ways: a click on a listing line (or on an event)
draws that line's stretch over the path and marks the line; a click on the path marks the
line it belongs to in the listing. The page loads plotly.js from `plotly.min.js` beside it
(written once), so the page itself stays small and the folder works offline.
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
(function () {
  const gd = document.getElementById(%(div)s);
  let marked = null;
  const data = document.getElementById('listing-data');
  if (data) {  // one row per source line: <tr id=L<n> data-line=<n> [class=moves]>
    const {lines, moves} = JSON.parse(data.textContent);
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
            lims: list[tuple[float, float] | None]) -> list[tuple[str, ...]]:
    """Per moving axis: letter, lowest and highest position of the cuts (feed moves), of
    all motion (rapids too), and the soft limits, as text in the drawn frame."""
    def num(x: float) -> str:
        return f"{x:.4f}" if math.isfinite(x) else ("-inf" if x < 0 else "inf")

    rows = []
    for k, letter in enumerate(run.letters):
        if np.ptp(pos[:, k]) <= 1e-9:
            continue
        p = pos[:, k] - off[k]
        c = p[cutting] if cutting.any() else p[:0]
        cut = (num(c.min()), num(c.max())) if c.size else ("-", "-")
        lim = lims[k]
        soft = ("-", "-") if lim is None else (num(lim[0] - off[k]), num(lim[1] - off[k]))
        rows.append((letter, *cut, num(p.min()), num(p.max()), *soft))
    return rows


def _extents_table(run: ProgramRunner, rows: list[tuple[str, ...]], frame: str) -> str:
    body = "".join("<tr>" + f"<td>{html.escape(r[0])}</td>" + "".join(
        f"<td class=num>{x}</td>" for x in r[1:]) + "</tr>" for r in rows)
    return (f"<h2>Extents ({html.escape(frame)} coordinates, {run.machine_units} or deg)</h2>"
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
    """The listing's place and its data (JSON; the script makes one row per line: markup
    per row written out here was 1.8 of the 2.8 MB of a 100k-line program's page)."""
    n = len(text.splitlines())
    more = (f"<p>... {n - MAX_LISTING_LINES} more lines not listed</p>"
            if n > MAX_LISTING_LINES else "")
    data = json.dumps(listing_data(run, text), separators=(",", ":")).replace("</", "<\\/")
    return ("<h2>Program</h2><p>Click a line to see its stretch on the path; click the path "
            "to find its line.</p><div id=listing><table></table></div>"
            f"<script type=application/json id=listing-data>{data}</script>{more}")


def program_text(run: ProgramRunner) -> str | None:
    """The program's source for the listing: the G-code file the runner read (a point
    table's lines are its generated G-code, not the file, so it has none)."""
    f = Path(run.file) if run.file else None
    if f is None or f.suffix.lower() in (".toml", ".csv") or not f.is_file():
        return None
    return f.read_text(encoding="utf-8", errors="replace")


def write_page(run: ProgramRunner, summary: RunSummary, summary_text: str, err: np.ndarray,
               path: Path, options: str = "", origin: np.ndarray | None = None) -> Path:
    """Write the page to `path` and plotly.min.js beside it; the page's path."""
    from .report_html import _figures, soft_limits

    del summary  # the text holds it; kept in the signature for callers that format apart
    title = html.escape(run.file or "program")
    frame = "machine" if origin is None else "program"
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>openmotion run: "
             f"{title}</title><script src='plotly.min.js'></script><style>{_STYLE}</style>"
             f"</head><body><h1>openmotion run: {title}</h1>"]
    if options:
        parts.append(f"<p>{html.escape(options)}</p>")
    parts.append(f"<pre>{html.escape(summary_text)}</pre>")
    _, idx, pos = run.trace()
    if len(pos):
        off = np.zeros(pos.shape[1]) if origin is None else np.asarray(origin, dtype=float)
        ops = [run.op_of.get(int(i)) for i in idx]
        cutting = np.array([o is not None and not o.rapid and o.kind in ("line", "arc")
                            for o in ops], dtype=bool)
        rows = extents(run, pos, cutting, off, soft_limits(run))
        if rows:
            parts.append(_extents_table(run, rows, frame))
    for heading, fig in _figures(run, err, origin):
        parts.append(f"<h2>{html.escape(heading)}</h2>")
        div = {"div_id": PATH_DIV} if heading == "Path" else {}
        parts.append(fig.to_html(full_html=False, include_plotlyjs=False,  # type: ignore[attr-defined]
                                 config={"displaylogo": False, "responsive": True}, **div))
    parts.append(_events_table(run))
    text = program_text(run)
    if text is not None:
        parts.append(_listing(run, text))
    parts.append(f"<script>{_SCRIPT % {'div': json.dumps(PATH_DIV)}}</script></body></html>")
    path.write_text("\n".join(parts), encoding="utf-8")
    write_plotly_js(path.parent)
    return path


def write_plotly_js(folder: Path) -> Path:
    """plotly.min.js in `folder` (once: an existing copy of the same size is kept)."""
    from plotly.offline import get_plotlyjs

    js = get_plotlyjs()
    out = folder / "plotly.min.js"
    if not (out.exists() and out.stat().st_size == len(js.encode("utf-8"))):
        out.write_text(js, encoding="utf-8")
    return out
