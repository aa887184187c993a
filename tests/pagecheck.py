"""Checks the HTML page tests share: a page is one self-contained file (plotly.js embedded,
nothing loaded from elsewhere), its figures' trace types, and drawing it in chromium."""

from __future__ import annotations

import base64
import gzip
import json
import re
from pathlib import Path

_FIGURE = re.compile(r"<script type=application/vnd.plotly\+json data-div=\"([^\"]+)\">(.*?)"
                     r"</script>", re.S)


def assert_self_contained(text: str) -> None:
    """No external script, style sheet, image or frame: no src= or href= attribute, no
    <link>, no url(...); plotly.js is embedded (the gzip data script and its loader)."""
    markup = re.sub(r"<script type=application/(?:gzip|json|vnd\.plotly\+json)[^>]*>.*?"
                    r"</script>", "", text, flags=re.S)
    tags = re.findall(r"<[a-zA-Z][^>]*>", markup)
    assert not [t for t in tags if re.search(r"\b(src|href)\s*=", t)], tags
    assert "<link" not in markup and "url(" not in markup and "import(" not in markup
    assert "<script type=application/gzip id=om-plotly-gz>" in text
    assert "DecompressionStream('gzip')" in text


def inflate(text: str, div: str) -> str:
    """The text of the page's gzip + base64 data script `div` (plotly_embed.gzip_b64)."""
    m = re.search(rf"<script type=application/gzip id={div}>(.*?)</script>", text, re.S)
    assert m, div
    return gzip.decompress(base64.b64decode(m.group(1))).decode("utf-8")


def figures(text: str) -> dict[str, dict]:
    """The page's figures by div id, as the loader draws them."""
    return {div: json.loads(data.replace("<\\/", "</")) for div, data in _FIGURE.findall(text)}


def trace_types(text: str) -> set[str]:
    return {t.get("type", "scatter") for f in figures(text).values() for t in f["data"]}


def draw(page: Path, tab) -> dict:
    """Open `page` in `tab` (conftest's session tab, left at about:blank afterwards); once
    the loader has drawn every figure: plotly's version, per figure div its trace count and
    whether an svg was drawn, and the page's errors."""
    errors: list[str] = []

    def on_error(e: object) -> None:
        errors.append(str(e))

    tab.on("pageerror", on_error)
    try:
        tab.goto(page.as_uri())   # after "load": the head's loader has set openmotionPlotly
        # awaited in the page, not polled: while plotly inflates and draws, the page's main
        # thread is busy for seconds on a loaded machine (a 30 s poll timed out once, load 20);
        # the race only keeps a page that never draws from hanging the test
        out = tab.evaluate("""async () => {
          if (!window.openmotionPlotly) return {version: null, figures: {}, loader: false};
          const late = new Promise((_, no) => setTimeout(() => no(new Error(
            'the figures were not drawn within 120 s')), 120000));
          await Promise.race([window.openmotionPlotly, late]);
          const figs = {};
          for (const d of document.querySelectorAll('.plotly-graph-div'))
            figs[d.id] = {traces: (d.data || []).length,
                          drawn: !!d.querySelector('.main-svg')};
          return {version: Plotly.version, figures: figs};
        }""")
        out["errors"] = errors
        return out
    finally:
        tab.remove_listener("pageerror", on_error)
        tab.goto("about:blank")


def array(v: object) -> list:
    """A figure array as plotly writes it: a list, or {dtype, bdata} (base64 binary)."""
    import numpy as np

    if isinstance(v, dict) and "bdata" in v:
        return np.frombuffer(base64.b64decode(v["bdata"]), dtype=v["dtype"]).tolist()
    return list(v)  # type: ignore[call-overload]
