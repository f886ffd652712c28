"""ParaView data collections (.pvd): a time series of VTK XML files, for ParaView and 3D Slicer.

A .pvd lists ``<DataSet timestep=... file=...>`` entries; ParaView opens it as
one source whose time is the timestep (here q) and loads each file when its time
is shown.  File paths are relative to the .pvd's folder, with forward slashes.
The XML is written by the standard library's ElementTree with a fixed
attribute order: the same entries give the same bytes.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence


def pvd_bytes(entries: Sequence[tuple[float, str]]) -> bytes:
    """The .pvd text for ``(time, relative file)`` pairs, times written as Python's shortest round-trip float."""
    root = ET.Element("VTKFile", {"type": "Collection", "version": "0.1", "byte_order": "LittleEndian"})
    collection = ET.SubElement(root, "Collection")
    for time, file in entries:
        ET.SubElement(collection, "DataSet", {"timestep": repr(float(time)), "group": "", "part": "0", "file": file})
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True) + b"\n"
