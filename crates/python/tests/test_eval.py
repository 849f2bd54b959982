"""`Brdf.eval` against Rust's `Brdf::eval` (the eval_pairs example) for every kind of source,
and the MERL table through NumPy and back."""

import subprocess

import numpy as np
import pytest

import facet_brdf
from conftest import GOLD, PLASTIC, PROXY, program, random_pairs, reference_eval

N = 10_000
# The MERL scales (1, 1.15, 1.66) / 1500: a file's values times these are f_r.
SCALE = np.array([1.0, 1.15, 1.66]) / 1500.0


def kinds(files):
    return {
        "analytic": GOLD,
        "analytic-plastic": PLASTIC,
        # Anisotropic and rotated: a swapped axis or component shows.
        "analytic-aniso": "analytic:beckmann?alpha_x=0.1&alpha_y=0.4&rotation=30&f0=0.9,0.5,0.2",
        "nbrdf": PROXY,
        "merl": str(files["merl"]),
        "rgl": str(files["bsdf"]),
        "fit-json": str(files["fit"]),
    }


@pytest.mark.parametrize(
    "kind",
    ["analytic", "analytic-plastic", "analytic-aniso", "nbrdf", "merl", "rgl", "fit-json"],
)
def test_eval_equals_rust_on_random_pairs(kind, files, tmp_path):
    source = kinds(files)[kind]
    wi, wo = random_pairs(N, seed=7)
    ours = facet_brdf.load(source).eval(wi, wo)
    assert ours.shape == (N, 3) and ours.dtype == np.float64
    ref = reference_eval(source, wi, wo, tmp_path)
    # The same f64 code on the same inputs: equal to round-off, NaN where Rust gives None.
    np.testing.assert_array_equal(np.isnan(ours), np.isnan(ref))
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=0, equal_nan=True)
    below = (wi[:, 2] <= 0) | (wo[:, 2] <= 0)
    assert below.any() and np.isnan(ours[below]).all()
    assert np.isfinite(ours[~below]).mean() > 0.9


def test_eval_takes_lists_and_checks_shapes():
    gold = facet_brdf.load(GOLD)
    f = gold.eval([[0.0, 0.0, 1.0]], [[0.0, 0.0, 1.0]])
    assert f.shape == (1, 3) and (f > 0).all()
    with pytest.raises(facet_brdf.FacetError, match=r"\(N, 3\)"):
        gold.eval(np.zeros((4, 2)), np.zeros((4, 2)))
    with pytest.raises(facet_brdf.FacetError, match="pairs"):
        gold.eval(np.zeros((4, 3)), np.zeros((5, 3)))


def write_merl(path, table):
    """A MERL file from an f_r array, by NumPy alone: the header, then value / scale."""
    stored = np.where(table < 0, -1.0, table / SCALE[:, None, None, None])
    with open(path, "wb") as f:
        np.array([90, 90, 180], dtype="<i4").tofile(f)
        stored.astype("<f8").tofile(f)


def test_from_merl_reads_the_file_layout(files, tmp_path):
    """from_merl of an array equals the file NumPy writes from it, read by Rust."""
    table = facet_brdf.load(files["merl"]).to_merl()
    assert table.shape == (3, 90, 90, 180)
    # The file's stored values, read with NumPy, times the scales.
    raw = np.fromfile(files["merl"], dtype="<f8", offset=12).reshape(3, 90, 90, 180)
    np.testing.assert_allclose(
        table, np.where(raw < 0, -1.0, raw * SCALE[:, None, None, None]), rtol=0, atol=0
    )
    # Make some samples missing, as a measurement has them.
    table[:, 40:45, 60:, :] = -1.0
    path = tmp_path / "holes.binary"
    write_merl(path, table)
    wi, wo = random_pairs(N, seed=11)
    ours = facet_brdf.from_merl(table).eval(wi, wo)
    ref = reference_eval(path, wi, wo, tmp_path)
    np.testing.assert_array_equal(np.isnan(ours), np.isnan(ref))
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=0, equal_nan=True)


@pytest.mark.parametrize("source", ["merl", "analytic"])
def test_from_merl_of_to_merl_round_trips(source, files):
    brdf = facet_brdf.load(files["merl"] if source == "merl" else GOLD)
    table = brdf.to_merl()
    again = facet_brdf.from_merl(table).to_merl()
    np.testing.assert_array_equal(table < 0, again < 0)
    # The scale is divided out and multiplied back in: a unit in the last place at most.
    np.testing.assert_allclose(again, table, rtol=4e-16, atol=0)
    if source == "merl":
        wi, wo = random_pairs(N, seed=3)
        np.testing.assert_allclose(
            facet_brdf.from_merl(table).eval(wi, wo),
            brdf.eval(wi, wo),
            rtol=1e-14,
            equal_nan=True,
        )


def test_saved_formats_read_back(files, tmp_path):
    merl = facet_brdf.load(files["merl"])
    copy = tmp_path / "copy.binary"
    merl.save(copy)
    assert copy.read_bytes() == files["merl"].read_bytes()
    with pytest.raises(facet_brdf.FacetError, match="extension"):
        merl.save(tmp_path / "x.exr")


@pytest.mark.parametrize("ext", ["binary", "bsdf"])
def test_save_writes_what_facet_convert_writes(ext, tmp_path):
    facet = program("FACET_BIN")
    ours, theirs = tmp_path / f"ours.{ext}", tmp_path / f"theirs.{ext}"
    facet_brdf.load(PLASTIC).save(ours)
    subprocess.run([facet, "convert", PLASTIC, str(theirs)], check=True, capture_output=True)
    assert ours.read_bytes() == theirs.read_bytes()
