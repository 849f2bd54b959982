"""Errors are FacetError (a ValueError) with the message the `facet` command prints."""

import subprocess

import numpy as np
import pytest

import facet_brdf
from conftest import GOLD, program


def test_facet_error_is_a_value_error():
    assert issubclass(facet_brdf.FacetError, ValueError)


def test_a_bad_file_raises_facet_error_naming_it(tmp_path):
    bad = tmp_path / "bad.binary"
    bad.write_bytes(b"\x01\x02\x03")
    with pytest.raises(facet_brdf.FacetError) as e:
        facet_brdf.load(bad)
    assert str(bad) in str(e.value) and "MERL" in str(e.value)
    bsdf = tmp_path / "bad.bsdf"
    bsdf.write_bytes(b"not a tensor file")
    with pytest.raises(facet_brdf.FacetError, match="bad.bsdf"):
        facet_brdf.load(bsdf)
    fit_json = tmp_path / "bad.json"
    fit_json.write_text("{}")
    with pytest.raises(facet_brdf.FacetError, match="bad.json"):
        facet_brdf.load(fit_json)


def test_a_missing_file_is_a_facet_error_too(tmp_path):
    missing = tmp_path / "missing.binary"
    with pytest.raises(facet_brdf.FacetError, match="missing.binary"):
        facet_brdf.load(missing)


def test_the_message_is_the_one_facet_prints(tmp_path):
    facet = program("FACET_BIN")
    bad = tmp_path / "bad.binary"
    bad.write_bytes(b"\x01\x02\x03")
    with pytest.raises(facet_brdf.FacetError) as e:
        facet_brdf.load(bad)
    run = subprocess.run(
        [facet, "fit", str(bad), "--out", str(tmp_path / "out")], capture_output=True, text=True
    )
    assert run.returncode != 0
    assert f"error: {e.value}" in run.stderr, run.stderr


def test_bad_arguments_raise_facet_error():
    with pytest.raises(facet_brdf.FacetError, match="shape"):
        facet_brdf.from_merl(np.zeros((3, 90, 90)))
    with pytest.raises(facet_brdf.FacetError, match="NaN|nan"):
        facet_brdf.from_merl(np.full((3, 90, 90, 180), np.nan))
    with pytest.raises(facet_brdf.FacetError, match="backscattering"):
        facet_brdf.from_merl(np.full((3, 90, 90, 180), -1.0))
    with pytest.raises(facet_brdf.FacetError, match="analytic"):
        facet_brdf.load("analytic:nonsense")
    with pytest.raises(facet_brdf.FacetError, match="gpu"):
        facet_brdf.fit(GOLD, backend="gpu")
    with pytest.raises(facet_brdf.FacetError, match="coat"):
        facet_brdf.fit(GOLD, coat="sometimes")
