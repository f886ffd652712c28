"""The designed case file: the user's text with new link breaks, everything else as written."""

from __future__ import annotations

from pathlib import Path

import yaml

from softdesign.io.case_edit import case_text_with_breaks

BREAKS = [0.0, 0.3333333333, 0.7, 1.0]
WRITTEN = [0.0, 0.333333, 0.7, 1.0]

CASE = """\
# my patient, left iliac
name: p01   # the build folder
final:
  centerline: data/centerline.vtp   # from VMTK
  surface: data/surface.stl
links:
  count: 4   # by hand

  # the fit: fine knots
fit: {knot_spacing_mm: 1.5}
"""


def _data(tmp_path: Path) -> Path:
    (tmp_path / "data").mkdir()
    for name in ("centerline.vtp", "surface.stl"):
        (tmp_path / "data" / name).write_text("x")
    return tmp_path


def test_block_links_are_replaced_and_every_other_line_is_kept(tmp_path):
    folder = _data(tmp_path)
    text, kept = case_text_with_breaks(CASE, BREAKS, folder, folder)
    assert kept
    expected = CASE.replace("links:\n  count: 4   # by hand\n", "links: {breaks: [0.0, 0.333333, 0.7, 1.0]}\n")
    assert text == expected
    assert yaml.safe_load(text)["links"] == {"breaks": WRITTEN}


def test_flow_links_are_replaced_in_place_and_absent_links_are_added(tmp_path):
    folder = _data(tmp_path)
    flow = CASE.replace("links:\n  count: 4   # by hand\n", "links: {length_mm: 20}  # by hand\n")
    text, kept = case_text_with_breaks(flow, BREAKS, folder, folder)
    assert kept and "links: {breaks: [0.0, 0.333333, 0.7, 1.0]}  # by hand\n" in text
    absent = CASE.replace("links:\n  count: 4   # by hand\n", "")
    text, kept = case_text_with_breaks(absent, BREAKS, folder, folder)
    assert kept and text == absent + "links: {breaks: [0.0, 0.333333, 0.7, 1.0]}\n"


def test_relative_input_paths_are_rebased_when_written_elsewhere(tmp_path):
    folder = _data(tmp_path)
    (folder / "designs" / "v1").mkdir(parents=True)
    text, kept = case_text_with_breaks(CASE, BREAKS, folder, folder / "designs" / "v1")
    assert kept and "# from VMTK" in text and "# my patient, left iliac" in text
    final = yaml.safe_load(text)["final"]
    assert final == {"centerline": "../../data/centerline.vtp", "surface": "../../data/surface.stl"}
    assert (folder / "designs" / "v1" / final["centerline"]).resolve() == (folder / "data" / "centerline.vtp").resolve()


def test_yaml_the_text_edit_cannot_check_is_written_whole_with_the_same_values(tmp_path):
    folder = _data(tmp_path)
    anchored = "name: p01\nrule: &r {count: 4}\nfinal: {centerline: data/centerline.vtp}\nlinks: *r\n"
    text, kept = case_text_with_breaks(anchored, BREAKS, folder, folder)
    loaded = yaml.safe_load(text)
    assert loaded["links"] == {"breaks": WRITTEN} and loaded["rule"] == {"count": 4}
    flow_root = "{name: p01, final: {centerline: data/centerline.vtp}, links: {count: 4}}\n"
    text, kept = case_text_with_breaks(flow_root, BREAKS, folder, folder)
    assert not kept and yaml.safe_load(text) == {"name": "p01", "final": {"centerline": "data/centerline.vtp"},
                                                  "links": {"breaks": WRITTEN}}
