"""plotly.js inside the HTML pages (run report, profile and trace pages): one file, offline.

The pages embed plotly's official partial bundle plotly.js-gl3d-dist-min (MIT; the core,
scatter and scatter3d: every trace type the pages draw), shipped gzipped in `vendor/`
(tools/update_plotly_bundle.sh refreshes it from npm), as base64 in a data script. The
page's loader inflates it with the browser's DecompressionStream('gzip'), runs it, then
draws the figures, whose JSON sits in data scripts beside their divs (`figure_html`);
`window.openmotionPlotly` is a promise resolved once every figure is drawn. Other large
data (the report's listing) is embedded the same way (`gzip_b64`, openmotionInflate).
"""

from __future__ import annotations

import base64
import gzip
import json
import re
from functools import cache
from pathlib import Path
from typing import Any

VENDOR = Path(__file__).resolve().parent / "vendor"
BUNDLE = VENDOR / "plotly-gl3d.min.js.gz"

_LOADER = """
window.openmotionInflate = async (id) => {  // the text of a gzip + base64 data script
  const raw = atob(document.getElementById(id).textContent.trim());
  const bytes = new Uint8Array(raw.length);
  for (let i = 0; i < raw.length; i++) bytes[i] = raw.charCodeAt(i);
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('gzip'));
  return await new Response(stream).text();
};
window.openmotionPlotly = (async () => {
  const js = await window.openmotionInflate('om-plotly-gz');
  const s = document.createElement('script');
  s.textContent = js;
  document.head.append(s);  // runs now: window.Plotly
  if (document.readyState === 'loading')  // the figures below are not all parsed yet
    await new Promise(r => document.addEventListener('DOMContentLoaded', r, {once: true}));
  for (const el of document.querySelectorAll('script[type="application/vnd.plotly+json"]')) {
    const fig = JSON.parse(el.textContent);
    await Plotly.newPlot(document.getElementById(el.dataset.div), fig.data, fig.layout,
                         fig.config);
  }
  return window.Plotly;
})();
"""


def bundle_version() -> str:
    """The embedded bundle's npm package and version (vendor/VERSION)."""
    return (VENDOR / "VERSION").read_text(encoding="utf-8").strip()


@cache
def _bundle_b64() -> str:
    return base64.b64encode(BUNDLE.read_bytes()).decode("ascii")


@cache
def bundle_trace_types() -> frozenset[str]:
    """The trace types the embedded bundle registers (read from its code)."""
    js = gzip.decompress(BUNDLE.read_bytes()).decode("utf-8")
    return frozenset(re.findall(r'moduleType:"trace",name:"(\w+)"', js))


def head_scripts() -> str:
    """The bundle (base64 of the gzipped file) and its loader, for the page's <head>."""
    return (f"<script type=application/gzip id=om-plotly-gz>{_bundle_b64()}</script>"
            f"<script>{_LOADER}</script>")


def figure_html(fig: Any, div_id: str, config: dict[str, Any] | None = None) -> str:
    """A figure's div and its JSON (drawn by the loader once plotly.js runs)."""
    from plotly.io.json import to_json_plotly

    spec = fig.to_dict()  # numpy arrays as {dtype, bdata}, as to_html writes them
    data = to_json_plotly({"data": spec.get("data", []), "layout": spec.get("layout", {}),
                           "config": config or {"displaylogo": False, "responsive": True}})
    data = data.replace("</", "<\\/")
    return (f"<div id={json.dumps(div_id)} class=plotly-graph-div></div>"
            f"<script type=application/vnd.plotly+json data-div={json.dumps(div_id)}>"
            f"{data}</script>")


def gzip_b64(text: str) -> str:
    """`text` gzipped and base64-encoded, for a data script `window.openmotionInflate`
    reads (no time stamp: the same text gives the same page)."""
    return base64.b64encode(gzip.compress(text.encode("utf-8"), 9, mtime=0)).decode("ascii")


def after_drawing(js: str) -> str:
    """A script running `js` once every figure is drawn."""
    return f"<script>window.openmotionPlotly.then(() => {{{js}}});</script>"
