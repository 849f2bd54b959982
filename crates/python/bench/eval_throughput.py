"""Brdf.eval throughput on 10^6 random pairs, beside Mitsuba 3's `measured` plugin on the same
.bsdf (docs/log/python.md). Run once per thread count, since rayon reads RAYON_NUM_THREADS
when its pool starts:

    RAYON_NUM_THREADS=1 python crates/python/bench/eval_throughput.py MERL.binary OUT_DIR
    RAYON_NUM_THREADS=2 python crates/python/bench/eval_throughput.py MERL.binary OUT_DIR mitsuba

(`mitsuba+llvm` also times Mitsuba's llvm_ad_rgb variant, vectorised.)

The MERL file goes through NumPy (`from_merl(load(file).to_merl())`); the .bsdf is the same
material written as `facet convert` writes it (into OUT_DIR, once).
"""

import os
import sys
import time
from pathlib import Path

import numpy as np

import facet_brdf

N = 1_000_000


def pairs(n, seed=1):
    rng = np.random.default_rng(seed)

    def dirs():
        theta = np.arccos(rng.uniform(0.0, 1.0, n))
        phi = rng.uniform(0.0, 2.0 * np.pi, n)
        return np.stack(
            [np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)], axis=1
        )

    return dirs(), dirs()


def best_of(k, f):
    """The least wall time of k runs, and the CPU time (all threads) of that run: on a shared
    machine the wall time includes waiting for a core."""
    times = []
    for _ in range(k):
        t, c = time.perf_counter(), time.process_time()
        f()
        times.append((time.perf_counter() - t, time.process_time() - c))
    return min(times)


def main():
    merl_file, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    threads = os.environ.get("RAYON_NUM_THREADS", "all")
    wi, wo = pairs(N)
    merl = facet_brdf.from_merl(facet_brdf.load(merl_file).to_merl())
    bsdf_file = out / (merl_file.stem + ".bsdf")
    if not bsdf_file.exists():
        facet_brdf.load(merl_file).save(bsdf_file)
    rgl = facet_brdf.load(bsdf_file)
    for name, b in [("merl (from_merl)", merl), ("rgl .bsdf", rgl)]:
        b.eval(wi[:1000], wo[:1000])
        t, cpu = best_of(3, lambda: b.eval(wi, wo))
        print(
            f"facet_brdf {name}, {threads} thread(s): {N / t / 1e6:.2f} M pairs/s "
            f"({t:.3f} s wall, {cpu:.3f} s CPU)"
        )
    if len(sys.argv) > 3 and sys.argv[3] in ("mitsuba", "mitsuba+llvm"):
        mitsuba(bsdf_file, wi, wo, rgl, llvm=sys.argv[3] == "mitsuba+llvm")


def mitsuba(bsdf_file, wi, wo, rgl, llvm):
    import drjit as dr
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    bsdf = mi.load_dict({"type": "measured", "filename": str(bsdf_file)})
    ctx = mi.BSDFContext()
    n = 20_000
    out = np.empty((n, 3))
    t, c = time.perf_counter(), time.process_time()
    for k in range(n):
        si = mi.SurfaceInteraction3f()
        si.wi = mi.Vector3f(*wi[k])
        f = bsdf.eval(ctx, si, mi.Vector3f(*wo[k]))
        out[k] = (f[0], f[1], f[2])
    t, c = time.perf_counter() - t, time.process_time() - c
    print(
        f"mitsuba scalar_rgb measured, Python loop over {n} pairs: {n / t / 1e6:.3f} M pairs/s "
        f"({t:.3f} s wall, {c:.3f} s CPU)"
    )
    ours = rgl.eval(wi[:n], wo[:n]) * wo[:n, 2:3]
    big = ours.max(axis=1) > 1e-3
    rel = np.abs(out - ours).max(axis=1)[big] / ours.max(axis=1)[big]
    print(f"  f cos θo against facet_brdf: median relative difference {np.median(rel):.2e}")
    if not llvm:
        return
    # On 2026-12-07 this aborted the process (LLVM ERROR: Cannot select fminimum) with the
    # system's libLLVM: hence a separate argument.
    try:
        mi.set_variant("llvm_ad_rgb")
    except Exception as e:  # no LLVM on this machine
        print(f"mitsuba llvm_ad_rgb: not available ({e})")
        return
    bsdf = mi.load_dict({"type": "measured", "filename": str(bsdf_file)})
    ctx = mi.BSDFContext()

    def run():
        si = dr.zeros(mi.SurfaceInteraction3f, N)
        si.wi = mi.Vector3f(wi[:, 0], wi[:, 1], wi[:, 2])
        f = bsdf.eval(ctx, si, mi.Vector3f(wo[:, 0], wo[:, 1], wo[:, 2]))
        dr.eval(f)
        return f

    run()
    t, cpu = best_of(3, run)
    print(
        f"mitsuba llvm_ad_rgb measured, vectorised: {N / t / 1e6:.2f} M pairs/s "
        f"({t:.3f} s wall, {cpu:.3f} s CPU)"
    )


if __name__ == "__main__":
    main()
