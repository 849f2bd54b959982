"""Issue 12's gold scene in Mitsuba 3, for the side-by-side noise comparison with
`facet bench --only noise` (its first scene): a GGX gold sphere (alpha 0.3) on a 20 x 20 grey
Lambertian floor, a constant sky of 0.5 and a 40 W/sr point light, 128 x 128, 16 spp.

Per-pixel variance is estimated as Facet's bench does: two renders with seeds 0 and 1,
E[(a - b)^2] / 2 averaged over pixels and channels. Facet's max_depth counts bounces after the
camera ray, Mitsuba's path vertices, so Mitsuba's is Facet's + 1 (6); Russian roulette from
Facet's depth 3 is Mitsuba's rr_depth 4. The pixel filter is a box, as Facet's: Mitsuba's
default Gaussian spreads each sample over neighbouring pixels and lowers per-pixel variance.

    pip install mitsuba==3.9.1 && python3 docs/bench/mitsuba_gold.py
"""
import time

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
from mitsuba import ScalarTransform4f as T  # noqa: E402


def scene(rr_depth, pixel_filter):
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 6, "rr_depth": rr_depth},
        "sensor": {
            "type": "perspective",
            "fov": 40.0,
            "fov_axis": "y",
            "to_world": T().look_at(origin=[0, 1.5, 5], target=[0, 0, 0], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": 128, "height": 128,
                     "rfilter": {"type": pixel_filter}},
            "sampler": {"type": "independent", "sample_count": 16},
        },
        "floor": {
            "type": "rectangle",
            "to_world": T().translate([0, -1, 0]).rotate([1, 0, 0], -90).scale(10),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.5}},
        },
        "sphere": {
            "type": "sphere", "radius": 1.0,
            "bsdf": {"type": "roughconductor", "distribution": "ggx", "alpha": 0.3,
                     "material": "Au"},
        },
        "light": {"type": "point", "position": [2, 3, 2], "intensity": {"type": "rgb", "value": 40.0}},
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": 0.5}},
    })


for rr_depth, pixel_filter in [(4, "box"), (5, "box"), (5, "gaussian")]:
    s = scene(rr_depth, pixel_filter)
    images, seconds = [], 0.0
    for seed in [0, 1]:
        t = time.perf_counter()
        images.append(np.array(mi.render(s, seed=seed), dtype=np.float64))
        seconds += time.perf_counter() - t
    a, b = images
    var = float(np.mean(0.5 * (a - b) ** 2))
    mean = float(np.mean(0.5 * (a + b)))
    print(f"mitsuba {mi.__version__} scalar_rgb, rr_depth {rr_depth}, {pixel_filter} filter: "
          f"variance {var:.3e}, mean {mean:.4f}, {seconds / 2:.2f} s a render")
