"""Mitsuba 3's `measured` plugin against Facet's reader on the same `.bsdf`.

Reads the lines of the `bsdf_eval` example from stdin (wi, wo, f cos θo per channel, pdf),
evaluates the file in Mitsuba's scalar_rgb variant at the same directions and prints the
median and 99th-percentile relative differences of f cos θo and of the pdf.

    cargo run --release -p facet-fit --example bsdf_eval -- FILE.bsdf \
        | python3 crates/fit/examples/mitsuba_check.py FILE.bsdf
"""
import sys

import mitsuba as mi

mi.set_variant("scalar_rgb")
bsdf = mi.load_dict({"type": "measured", "filename": sys.argv[1]})
ctx = mi.BSDFContext()
value_err, pdf_err = [], []
for line in sys.stdin:
    x = [float(v) for v in line.split()]
    si = mi.SurfaceInteraction3f()
    si.wi = mi.Vector3f(x[0], x[1], x[2])
    wo = mi.Vector3f(x[3], x[4], x[5])
    f = bsdf.eval(ctx, si, wo)
    pdf = bsdf.pdf(ctx, si, wo)
    ours = x[6:9]
    scale = max(ours)
    if scale > 1e-3:
        value_err.append(max(abs(float(f[c]) - ours[c]) for c in range(3)) / scale)
    if x[9] > 1e-3:
        pdf_err.append(abs(float(pdf) - x[9]) / x[9])


def q(v, p):
    v = sorted(v)
    return v[min(len(v) - 1, int(p * (len(v) - 1)))]


print(f"f cos θo: {len(value_err)} pairs, median {q(value_err, 0.5):.2e}, p99 {q(value_err, 0.99):.2e}, max {q(value_err, 1.0):.2e}")
print(f"pdf:      {len(pdf_err)} pairs, median {q(pdf_err, 0.5):.2e}, p99 {q(pdf_err, 0.99):.2e}, max {q(pdf_err, 1.0):.2e}")
