"""A Mitsuba 3 ``<bsdf>`` file, as ``facet export`` writes it, read into the dict that
``mitsuba.load_dict`` takes (no Mitsuba needed to build it)."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from typing import Any, Dict, Optional


def xml_to_dict(text: str, table_dir: Optional[str] = None) -> Dict[str, Any]:
    """The ``<bsdf>`` root of ``text`` as a Mitsuba dict; a ``filename`` is made absolute in
    ``table_dir`` (where the ``measured`` table was written)."""
    root = ET.fromstring(text)
    if root.tag != "bsdf":
        raise ValueError(f"not a Mitsuba <bsdf>: <{root.tag}>")
    out: Dict[str, Any] = {"type": root.attrib["type"]}
    for child in root:
        name, value = child.attrib["name"], child.attrib["value"]
        if child.tag == "float":
            out[name] = float(value)
        elif child.tag == "integer":
            out[name] = int(value)
        elif child.tag == "boolean":
            out[name] = value.strip().lower() == "true"
        elif child.tag == "rgb":
            out[name] = {"type": "rgb", "value": [float(v) for v in value.split(",")]}
        elif child.tag == "string":
            if name == "filename" and table_dir is not None:
                value = os.path.join(os.fspath(table_dir), value)
            out[name] = value
        else:
            raise ValueError(f"unexpected <{child.tag}> in the exported <bsdf>")
    return out
