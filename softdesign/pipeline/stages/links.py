"""Stage 3, links: where the actuator is split, in normalized l (DESIGN.md stage 3, first half).

``links/links.json`` holds the breaks (n_links + 1 values of l in [0, 1]) and
each link's length on the final shape, mm.  The breaks are a product of
their own so that the fit and the kinematics both consume them: a change of
the export q values redoes the kinematics, not the fit.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from softdesign.kinematics.links import LinkChain, link_breaks
from softdesign.pipeline import layout
from softdesign.pipeline.stage import Stage
from softdesign.pipeline.stages.blend import BlendResult
from softdesign.pipeline.store import Staging

if TYPE_CHECKING:  # only annotations: the report loads stage results without the case file's models
    from softdesign.config import Case

VERSION = 1


@dataclass(frozen=True)
class LinksResult:
    """The chain of links on the blended shape and its JSON document."""

    chain: LinkChain
    document: dict[str, Any]


def run_links(case: Case, blend: BlendResult) -> LinksResult:
    """Split the blended shape into the case's links (``links.count``, ``breaks`` or ``length_mm``)."""
    rule = case.links
    total = blend.shape.keys[-1].length
    if blend.shape.mode == "pcc":  # one link per designed section
        breaks = np.array(blend.summary["design_breaks"], dtype=np.float64)
    else:
        breaks = link_breaks(total, rule.count, rule.breaks, rule.length_mm)
    document = {
        "breaks": breaks.tolist(),
        "lengths_mm": (np.diff(breaks) * total).tolist(),
        "units": {"breaks": "normalized arc length l of the final shape", "lengths_mm": "mm"},
    }
    if blend.shape.mode == "pcc":
        document["source"] = "design: one link per section (blend: pcc; the case's links: is not used)"
    return LinksResult(LinkChain(blend.shape, breaks), document)


def write_links(result: LinksResult, staging: Staging) -> None:
    """Write ``links/links.json``."""
    staging.write_json(layout.LINKS, result.document)


def load_links(build_dir: Path, blend: BlendResult) -> LinksResult:
    """The breaks from disk, on the (already loaded) blend."""
    document = json.loads((Path(build_dir) / layout.LINKS).read_text(encoding="utf-8"))
    return LinksResult(LinkChain(blend.shape, np.array(document["breaks"], dtype=np.float64)), document)


def describe_links(result: LinksResult) -> list[str]:
    """One line: the count, the breaks and the lengths."""
    breaks = ", ".join(f"{v:.4f}" for v in result.document["breaks"])
    lengths = ", ".join(f"{v:.2f}" for v in result.document["lengths_mm"])
    return [f"{len(result.document['lengths_mm'])} link(s): breaks l = [{breaks}], lengths [{lengths}] mm"]


STAGE = Stage(
    name="links",
    version=VERSION,
    reads=("links",),
    upstream=("blend",),
    compute=lambda case, results: run_links(case, results["blend"]),
    write=write_links,
    load=lambda build_dir, results: load_links(build_dir, results["blend"]),
    describe=describe_links,
    metrics=lambda result: {"count": len(result.document["lengths_mm"]), "breaks": result.document["breaks"]},
)
