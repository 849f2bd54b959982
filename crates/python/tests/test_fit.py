"""`fit` against `facet fit` on the same input: the same record but for the timings."""

import json
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

import facet_brdf
from conftest import GOLD, PLASTIC, program

ROOT = Path(__file__).resolve().parents[3]


def cli_record(source, out, args=()):
    facet = program("FACET_BIN")
    subprocess.run(
        [facet, "fit", str(source), *args, "--out", str(out)], check=True, capture_output=True
    )
    (json_file,) = out.glob("*.json")
    return json.loads(json_file.read_text())


def without_timings(record):
    return {k: v for k, v in record.items() if k != "timings_ms"}


def differences(a, b, path="", rtol=1e-6, atol=1e-9):
    """Where two records differ: structure, strings and integers exactly, floats beyond
    `rtol` and `atol`. `facet fit` itself sums over the MERL grid with rayon's fold/reduce,
    whose order follows work stealing, so two runs of it may differ at round-off, and a
    parameter the data barely determine moves more: a plastic's conductor k, 8.2061558e-06
    against 8.2061717e-06 (2e-6 relative, 1.6e-11 absolute), in one run of five on a loaded
    2-core machine."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{path}: keys {sorted(set(a) ^ set(b))}"]
        return [d for k in a for d in differences(a[k], b[k], f"{path}/{k}", rtol, atol)]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: lengths {len(a)}, {len(b)}"]
        return [
            d
            for i, (x, y) in enumerate(zip(a, b))
            for d in differences(x, y, f"{path}[{i}]", rtol, atol)
        ]
    if isinstance(a, float) and isinstance(b, float):
        close = abs(a - b) <= rtol * max(abs(a), abs(b)) + atol
        return [] if close else [f"{path}: {a!r} != {b!r}"]
    return [] if a == b and type(a) is type(b) else [f"{path}: {a!r} != {b!r}"]


# (source, fit's keywords, the same options on facet fit's command line)
CASES = {
    "analytic-gold": (GOLD, {}, []),
    "analytic-plastic": (PLASTIC, {}, []),
    "merl-file": ("merl", {}, []),
    "options": (
        PLASTIC,
        dict(coat="off", model="ggx", resolution=64, metric="log", fresnel="schlick"),
        ["--coat", "off", "--model", "ggx", "--resolution", "64", "--metric", "log",
         "--fresnel", "schlick"],
    ),
    "single-lobe": (GOLD, dict(no_diffuse=True, iterations=8), ["--no-diffuse", "--iterations", "8"]),
}


@pytest.mark.parametrize("which", list(CASES))
def test_record_equals_facet_fit(which, files, tmp_path):
    source, kwargs, args = CASES[which]
    source = files["merl"] if source == "merl" else source
    cli = cli_record(source, tmp_path / "out", args)
    ours = facet_brdf.fit(source, **kwargs).record
    assert set(ours["timings_ms"]) == set(cli["timings_ms"])
    assert differences(without_timings(ours), without_timings(cli)) == []
    # Most runs agree to the last digit.
    print(f"{which}: records bit-identical: {without_timings(ours) == without_timings(cli)}")


def test_fit_of_a_brdf_and_its_models(files, tmp_path):
    brdf = facet_brdf.load(files["merl"])
    fit = facet_brdf.fit(brdf, coat="off")
    assert fit.record["source"] == str(files["merl"])
    assert fit.record["name"] == "plastic"
    for model in ["tabulated", "ggx", "beckmann"]:
        m = fit.model(model)
        assert m.name == f"plastic-{model}"
        f = m.eval([[0.3, 0.0, 0.95]], [[-0.3, 0.0, 0.95]])
        assert (f > 0).all()
    with pytest.raises(facet_brdf.FacetError, match="coat"):
        fit.model("ggx", coated=True)
    with pytest.raises(facet_brdf.FacetError, match="tabulated, ggx, beckmann"):
        fit.model("phong")
    # Saved, the record reads back as the same fit.
    path = tmp_path / "plastic.json"
    fit.save(path)
    assert json.loads(path.read_text()) == fit.record
    assert path.read_text() == fit.to_json()
    again = facet_brdf.load(path)
    wi = np.array([[0.2, 0.1, 0.97]])
    np.testing.assert_array_equal(again.eval(wi, wi), fit.model("tabulated").eval(wi, wi))


def test_ndf_is_the_tables_csv(files, tmp_path):
    facet = program("FACET_BIN")
    out = tmp_path / "out"
    subprocess.run([facet, "fit", GOLD, "--out", str(out)], check=True, capture_output=True)
    (csv,) = out.glob("*.tables.csv")
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    d = facet_brdf.fit(GOLD).ndf(np.radians(table[:, 0]))
    # The CSV prints D with {:e}: its shortest round-tripping digits.
    np.testing.assert_array_equal(d, table[:, 1])
    theta = np.radians([[10.0, 20.0], [30.0, 40.0]])
    assert facet_brdf.fit(GOLD, coat="off").ndf(theta).shape == (2, 2)


def test_version_is_the_workspace_version():
    cargo = (ROOT / "Cargo.toml").read_text()
    section = cargo.split("[workspace.package]")[1]
    version = re.search(r'^version = "([^"]+)"', section, re.M).group(1)
    assert facet_brdf.__version__ == version


def test_a_coated_fit(tmp_path):
    """A proxy whose fit keeps a clear coat: its coated models, and its Mitsuba export, a
    `measured` BSDF on a table written into table_dir."""
    fit = facet_brdf.fit("nbrdf:gold-metallic-paint")
    assert fit.record.get("coat") is not None
    wi = np.array([[0.3, 0.0, 0.954], [0.0, 0.5, 0.866]])
    wo = np.array([[-0.3, 0.1, 0.949], [0.2, -0.4, 0.894]])
    coated = fit.model("ggx", coated=True)
    assert coated.source.endswith(":coated")
    assert np.isfinite(coated.eval(wi, wo)).all()
    with pytest.raises(facet_brdf.FacetError, match="table_dir"):
        fit.to_mitsuba(coat=True)
    d = fit.to_mitsuba(coat=True, table_dir=tmp_path)
    assert d["type"] == "measured"
    assert Path(d["filename"]).parent == tmp_path and Path(d["filename"]).is_file()
    # The table is a .bsdf this package reads too.
    assert np.isfinite(facet_brdf.load(d["filename"]).eval(wi, wo)).all()
    try:
        import mitsuba as mi
    except ImportError:
        return
    mi.set_variant("scalar_rgb")
    mi.load_dict(d)
