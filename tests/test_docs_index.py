"""docs/index.md links every documentation page, the README links the index, and the
machine-file reference names every machine-file key."""

import re
from pathlib import Path

from openmotion.config import AxisConfig, DCMotorConfig, DriveConfig, LoopConfig, SwitchConfig

DOCS = Path(__file__).resolve().parent.parent / "docs"


def test_index_links_every_page_and_every_link_exists():
    index = (DOCS / "index.md").read_text()
    links = set(re.findall(r"\]\(([\w.-]+\.md)\)", index))
    pages = {p.name for p in DOCS.glob("*.md")} - {"index.md"}
    assert pages <= links, pages - links
    assert all((DOCS / link).exists() for link in links)
    assert "seed" not in index.lower()
    assert "docs/index.md" in (DOCS.parent / "README.md").read_text()


def test_machine_file_reference_names_every_key():
    text = (DOCS / "machine-file.md").read_text()
    for cls in (AxisConfig, DriveConfig, DCMotorConfig, LoopConfig, SwitchConfig):
        for key in cls.__dataclass_fields__:
            if key in ("name", "logic", "drive", "loop", "motor", "pel", "mel", "org", "sd"):
                continue
            assert f"`{key}`" in text, f"{cls.__name__}.{key}"
    for key in ("cycle_s", "digital_inputs", "digital_outputs"):
        assert f"`{key}`" in text
