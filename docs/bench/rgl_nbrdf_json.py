"""Converts the RGL database's neural BRDF proxies (Sztrajman et al. 2021, asztr/Neural-BRDF,
`data/rgl-isotropic_nbrdf.zip`, MIT licence: fetch it, do not commit it) to the JSON format of
Facet's embedded MERL-100 proxies (crates/fit/data/nbrdf/README.md): one entry per material,
`name -> {W1, b1, W2, b2, W3, b3}` of the 6-21-21-3 network, values unchanged. The names drop
the files' `_rgb` suffix. Then any `facet` command takes them with `--nbrdf`:

    pip install h5py
    python3 docs/bench/rgl_nbrdf_json.py rgl-isotropic_nbrdf.zip rgl51.json
    facet fit --nbrdf rgl51.json nbrdf:cc_iris_purple_gem --out fits
"""
import io
import json
import sys
import zipfile

import h5py


def layers(h5):
    """(kernel, bias) of dense_1..3 as nested lists."""
    out = {}
    for k in (1, 2, 3):
        g = h5[f"dense_{k}"][f"dense_{k}"]
        out[f"W{k}"] = g["kernel:0"][()].tolist()
        out[f"b{k}"] = g["bias:0"][()].tolist()
    return out


def main(src, dst):
    nets = {}
    with zipfile.ZipFile(src) as z:
        for name in sorted(z.namelist()):
            if not name.endswith("_rgb.h5"):
                continue
            material = name.rsplit("/", 1)[-1][: -len("_rgb.h5")]
            with h5py.File(io.BytesIO(z.read(name)), "r") as h5:
                nets[material] = layers(h5)
    with open(dst, "w") as f:
        json.dump(nets, f)
    print(f"{len(nets)} materials -> {dst}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
