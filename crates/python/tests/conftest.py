"""Shared sources for the tests: one of each kind `facet fit` takes, made in a temporary
folder from an analytic model (no download), and the random direction pairs.

Two programs built by cargo give the references: `$FACET_BIN`, the `facet` command, and
`$FACET_EVAL_PAIRS`, the `eval_pairs` example of facet-fit (`Brdf::eval` pair by pair on one
thread). `.ci/run` sets both; a test that needs one skips, saying so, when it is unset.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import facet_brdf

# A conductor and a plastic (diffuse under a dielectric), both isotropic.
GOLD = "analytic:ggx?alpha=0.3&conductor=gold"
PLASTIC = "analytic:ggx?alpha=0.2&ior=1.5&kd=0.5,0.2,0.1"
# A neural proxy of the MERL database, embedded in Facet.
PROXY = "nbrdf:gold-metallic-paint3"


def program(var):
    """The program `$var` names, or a visible skip."""
    path = os.environ.get(var)
    if not path:
        pytest.skip(f"{var} is not set (.ci/run sets it to the program cargo built)")
    if not Path(path).is_file():
        pytest.fail(f"{var}={path}: no such program")
    return path


def random_pairs(n, seed):
    """n pairs of directions (N, 3), about 5 % of each below the horizon (eval's NaN)."""
    rng = np.random.default_rng(seed)

    def dirs():
        theta = np.arccos(rng.uniform(-0.1, 1.0, n))
        phi = rng.uniform(0.0, 2.0 * np.pi, n)
        return np.stack(
            [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1
        )

    return dirs(), dirs()


@pytest.fixture(scope="session")
def files(tmp_path_factory):
    """A MERL `.binary`, an RGL `.bsdf` and a fit `.json`, written by the package."""
    d = tmp_path_factory.mktemp("sources")
    plastic = facet_brdf.load(PLASTIC)
    merl = d / "plastic.binary"
    plastic.save(merl)
    bsdf = d / "gold.bsdf"
    facet_brdf.load(GOLD).save(bsdf)
    fit_json = d / "gold-fit.json"
    facet_brdf.fit(GOLD, coat="off").save(fit_json)
    return {"merl": merl, "bsdf": bsdf, "fit": fit_json, "dir": d}


def reference_eval(source, wi, wo, tmp_path):
    """`Brdf::eval` of `source` on the pairs, by the eval_pairs example."""
    exe = program("FACET_EVAL_PAIRS")
    pairs, out = tmp_path / "pairs.f64", tmp_path / "out.f64"
    np.concatenate([wi, wo], axis=1).astype("<f8").tofile(pairs)
    subprocess.run([exe, str(source), str(pairs), str(out)], check=True)
    return np.fromfile(out, dtype="<f8").reshape(-1, 3)
