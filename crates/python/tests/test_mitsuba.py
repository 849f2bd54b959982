"""`Fit.to_mitsuba` loads in Mitsuba 3 and agrees with `Fit.model("ggx")` within what the
export states it approximates.

The statement (`Fit.export`'s report) gives numbers for the Fresnel curve that stands in for
the F table (`fresnel_error`: the model with the curve against the data; `table_error`: the
model with its table) and for a plastic's diffuse term (its ratio to ρd/π at normal incidence),
and names Mitsuba's separable Smith G without a number. So the test takes the G ratio out in
closed form (GGX Λ), and then asks the specular part to lie within the stated Fresnel errors
and a plastic's diffuse part, near the normal, within 2 % of the stated ratio (it is not:
`test_plastic_diffuse_is_the_stated_ratio`, an expected failure).
"""

import re

import numpy as np
import pytest

import facet_brdf
from conftest import GOLD, PLASTIC, random_pairs

mi = pytest.importorskip("mitsuba", reason="mitsuba is not installed (pip install mitsuba)")


def mitsuba_eval(bsdf_dict, wi, wo):
    """f_r of the Mitsuba BSDF (its eval is f_r cos θo), pair by pair in scalar_rgb."""
    mi.set_variant("scalar_rgb")
    bsdf = mi.load_dict(bsdf_dict)
    ctx = mi.BSDFContext()
    out = np.empty((len(wi), 3))
    for n in range(len(wi)):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*wi[n])
        f = bsdf.eval(ctx, si, mi.Vector3f(*wo[n]))
        out[n] = [f[0], f[1], f[2]]
    return out / wo[:, 2:3]


def ggx_lambda(w, alpha):
    tan2 = (1.0 - w[:, 2] ** 2) / w[:, 2] ** 2
    return 0.5 * (-1.0 + np.sqrt(1.0 + alpha**2 * tan2))


def g_ratio(wi, wo, alpha):
    """Facet's height-direction-correlated G2 over Mitsuba's G1(wi) G1(wo)."""
    li, lo = ggx_lambda(wi, alpha), ggx_lambda(wo, alpha)
    phi = np.abs(np.arctan2(wi[:, 1], wi[:, 0]) - np.arctan2(wo[:, 1], wo[:, 0]))
    phi = np.where(phi > np.pi, 2.0 * np.pi - phi, phi)
    corr = 4.41 * phi / (4.41 * phi + 1.0)
    g2 = 1.0 / (1.0 + np.maximum(li, lo) + corr * np.minimum(li, lo))
    return g2 * (1.0 + li) * (1.0 + lo)


def metric(a, b, floor):
    """Facet's error metric: mean |ln(1 + x_a/ε) − ln(1 + x_b/ε)| over the pairs, x = f cos θi."""
    return np.mean(np.abs(np.log1p(a / floor) - np.log1p(b / floor)))


@pytest.mark.parametrize("source", [GOLD, PLASTIC])
def test_to_mitsuba_agrees_with_the_ggx_model(source):
    fit = facet_brdf.fit(source, coat="off")
    d = fit.to_mitsuba()
    _, report = fit.export("mitsuba", "ggx")
    assert d["distribution"] == "ggx" and d["alpha"] == report["alpha_x"]
    pairs_i, pairs_o = random_pairs(2000, seed=5)
    up = (pairs_i[:, 2] > 0.05) & (pairs_o[:, 2] > 0.05)
    wi, wo = pairs_i[up], pairs_o[up]
    alpha = report["alpha_x"]
    ggx = fit.model("ggx")
    ours = ggx.eval(wi, wo)
    theirs = mitsuba_eval(d, wi, wo)
    assert np.isfinite(theirs).all()
    rho = np.array(report["diffuse"]) / np.pi
    if d["type"] == "roughconductor":
        # The conductor drops ρd (stated in the notes when it is not ~0).
        spec_theirs, spec_ours = theirs, ours - rho
    else:
        assert d["type"] == "roughplastic"
        spec_theirs = mitsuba_eval({**d, "diffuse_reflectance": {"type": "rgb", "value": [0, 0, 0]}}, wi, wo)
        spec_ours = ours - rho
    floor = fit.record["metric_floor"]
    corrected = spec_theirs * g_ratio(wi, wo, alpha)[:, None]
    x = lambda f: f * wi[:, 2:3]
    distance = metric(x(corrected), x(spec_ours), floor)
    # Beyond the statement: Mitsuba computes in float32, and its plastic's specular differs by
    # up to 0.1 % at grazing θd (median 0.007 %; measured 2026-12-07, Mitsuba 3.9.1), which
    # the statement does not mention: 1e-4 in the metric covers both.
    stated = report["fresnel_error"] + report["table_error"] + 1e-4
    print(f"{source}: {d['type']}: distance {distance:.2e}, stated {stated:.2e}; "
          f"without the G ratio {metric(x(spec_theirs), x(spec_ours), floor):.2e}")
    assert distance <= stated, (distance, stated, report)


@pytest.mark.xfail(
    strict=True,
    reason="Mitsuba 3.9.1's roughplastic diffuse is 0.79 × ρd/π near the normal at η 1.5, "
    "α 0.2; the export states 1.015 (crates/fit/src/export/mitsuba.rs, plastic_diffuse_ratio)",
)
def test_plastic_diffuse_is_the_stated_ratio():
    fit = facet_brdf.fit(PLASTIC, coat="off")
    d = fit.to_mitsuba()
    _, report = fit.export("mitsuba", "ggx")
    assert d["type"] == "roughplastic"
    pairs_i, pairs_o = random_pairs(4000, seed=9)
    near = (pairs_i[:, 2] > 0.95) & (pairs_o[:, 2] > 0.95)
    wi, wo = pairs_i[near], pairs_o[near]
    black = {**d, "diffuse_reflectance": {"type": "rgb", "value": [0, 0, 0]}}
    diffuse = mitsuba_eval(d, wi, wo) - mitsuba_eval(black, wi, wo)
    ratio = float(re.search(r"about ([0-9.]+) × ρd/π", " ".join(report["notes"])).group(1))
    measured = diffuse / (np.array(report["diffuse"]) / np.pi)
    print(f"diffuse near the normal: {np.median(measured):.3f} × ρd/π, stated {ratio}")
    np.testing.assert_allclose(measured, ratio, rtol=0.02)
