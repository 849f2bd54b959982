"""Issue 47: measured RGL `.bsdf` materials side by side with Mitsuba 3's `measured` plugin.

One scene, written here for both renderers: a unit sphere (a UV sphere of --rings x 2 --rings
quads, the same triangles and vertex normals in the glTF Facet reads and in the PLY Mitsuba
reads, so silhouettes agree to the pixel), optionally a 20 x 20 grey Lambertian floor at
y = -1, a 40 W/sr point light at (2, 3, 2), a perspective camera at (0, 1.5, 5) looking at the
origin (fov 30 degrees vertical), and optionally a constant sky. The sphere's material is
measured: `"extras": {"facet": {"model": "measured", "source": "NAME.bsdf"}}` in the glTF,
`{"type": "measured", "filename": "NAME.bsdf"}` in Mitsuba: the same file. The .bsdf files are
written by `facet convert` (--material NAME=SOURCE, any `facet convert` input; a real RGL file
is taken as it is):

    pip install mitsuba==3.9.1
    python3 docs/bench/mitsuba_measured.py --facet-bin target/release/facet --spp 256 \\
        --json docs/bench/mitsuba-measured.json      # the committed numbers (128 x 128)

Everything is written under --workdir (out/mitsuba-measured): the .bsdf files, sphere.ply and
floor.ply, one glTF (+ .bin) per material and case, and Facet's renders.

Cases (--cases): `direct`: Facet max_depth 1, the sphere and the point light only, no floor, no
sky (f cos I / r^2 of the measured lobe, plus nothing); `full`: max_depth 5, the floor and a
constant sky of 0.5 (Facet's --env-color 0.5, Mitsuba's `constant`).

Conventions, as docs/bench/mitsuba_gold.py and mitsuba_many_lights.py: Facet's max_depth counts
bounces after the camera ray, Mitsuba's path vertices, so Mitsuba's is Facet's + 1, and so is
rr_depth (Facet plays Russian roulette from depth 3: Mitsuba's rr_depth 4); the pixel filter is
a box, as Facet's; both use the independent sampler at the same spp. Per-pixel variance is
E[(a - b)^2] / 2 over two renders with seeds 0 and 1, averaged over pixels and channels; means
are those of (a + b) / 2. KHR_lights_punctual `intensity x color` is Facet's radiant intensity
in W/sr (crates/render/src/scene/gltf_file.rs), as is Mitsuba's `point` intensity: the same
numbers. The floor is Lambertian in Facet (metallic 0, KHR_materials_specular specularFactor 0)
and a `twosided` `diffuse` in Mitsuba (Facet's surfaces are two-sided). Mitsuba's `measured`
is one-sided (zero when either direction is below the shading horizon); the sphere is closed and
seen from outside, so that does not matter here.

Statistics, per case and material: the mean of the channel-mean image over a 4 x 4 grid of
regions (top row first), the whole image, the sphere-only pixels (the rays through all four
corners of the pixel hit a sphere of radius 0.995, inside the tessellation) and the silhouette
pixels (the rest of those that a sphere of radius 1.005 touches), each with its standard error
from the two seeds, SE^2 = sum over the region's n pixels of (a - b)^2 / 4 / n^2 (channel-means
a, b), and z = (Facet - Mitsuba) / sqrt(SE_F^2 + SE_M^2); the variance over the image, the
sphere and the silhouette, with its standard error over pixels (std of the pixels'
(a - b)^2 / 2 / sqrt(n): a few bright-edge pixels dominate it, so it is ~10 % at 128 x 128),
and the ratio Facet / Mitsuba at equal spp. Times: Facet's is the wall time of a whole
`facet render` process (start-up, shader compilation, scene load, render, EXR write) and that
of its render stage (its own "timings" line), Mitsuba's that of mi.render (the scene is loaded
once before). On lavapipe (software Vulkan on the CPU) Facet's times say nothing of a GPU's.

What the committed numbers (docs/bench/mitsuba-measured.json; lavapipe, 2 CPU cores) say: the
means agree everywhere within noise (image and sphere ratios 0.9989 to 0.9998, |z| < 1.8; the
direct cases' sphere ratio 0.9998 is 2e-4, within the GPU reader's tested 3e-4 of the CPU one).
Variance at equal spp: direct lighting is only the pixel jitter (box filter, uniform in both),
ratio 0.88 to 0.94 +- 0.14, i.e. equal; with the floor and the sky Facet's is 0.34 to 0.46 x
Mitsuba's, its light selection (the point light by the light BVH, "asked 75 % of the time")
against Mitsuba's uniform choice between the point light and the sky. Single silhouette pixels
(grazing views of the measured lobe) can differ by a few % at 256 spp (e.g. three far-left
top ones in `full`, whose z in their 4 x 4 region is then overstated by the two-seed error);
the silhouette as a whole agrees within 0.3 %.
"""
import argparse
import json
import math
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
from mitsuba import ScalarTransform4f as T  # noqa: E402

EYE = np.array([0.0, 1.5, 5.0])
TARGET = np.array([0.0, 0.0, 0.0])
UP = np.array([0.0, 1.0, 0.0])
YFOV_DEG = 30.0
LIGHT_POSITION = [2.0, 3.0, 2.0]
LIGHT_INTENSITY = 40.0  # W/sr, every channel
SKY = 0.5
FLOOR_ALBEDO = 0.5
MASK_RADIUS = 0.995

DEFAULT_MATERIALS = ["ggx=analytic:ggx?alpha=0.2&f0=0.9", "paint=nbrdf:gold-metallic-paint"]
CASES = {
    "direct": {"max_depth": 1, "floor": False, "sky": False},
    "full": {"max_depth": 5, "floor": True, "sky": True},
}


# ---- geometry --------------------------------------------------------------------------------

def uv_sphere(rings):
    """Unit sphere: `rings` rings of 2 x rings segments, one triangle per pole cell (no
    degenerate triangles), counter-clockwise seen from outside; normals = positions."""
    segs = 2 * rings
    pos = [[0.0, 1.0, 0.0]]
    for i in range(1, rings):
        th = math.pi * i / rings
        for j in range(segs):
            ph = 2.0 * math.pi * j / segs
            pos.append([math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)])
    pos.append([0.0, -1.0, 0.0])
    pos = np.array(pos, dtype=np.float64)
    ring = lambda i, j: 1 + (i - 1) * segs + (j % segs)  # noqa: E731  (ring i = 1..rings-1)
    bottom = len(pos) - 1
    faces = []
    for j in range(segs):
        faces.append([0, ring(1, j), ring(1, j + 1)])
        faces.append([bottom, ring(rings - 1, j + 1), ring(rings - 1, j)])
        for i in range(1, rings - 1):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [[a, c, d], [a, d, b]]
    faces = np.array(faces, dtype=np.int64)
    # Orient outward (counter-clockwise seen from outside): flip any face whose normal points in.
    p0, p1, p2 = pos[faces[:, 0]], pos[faces[:, 1]], pos[faces[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(p1 - p0, p2 - p0), p0 + p1 + p2) < 0
    faces[inward] = faces[inward][:, [0, 2, 1]]
    return pos, pos.copy(), faces


def floor_quad():
    pos = np.array([[-10, -1, -10], [-10, -1, 10], [10, -1, 10], [10, -1, -10]], dtype=np.float64)
    nrm = np.tile([0.0, 1.0, 0.0], (4, 1))
    return pos, nrm, np.array([[0, 1, 2], [0, 2, 3]], dtype=np.int64)


def camera_basis():
    forward = (TARGET - EYE) / np.linalg.norm(TARGET - EYE)
    right = np.cross(forward, UP)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    return right, up, forward


def write_ply(path, positions, normals, faces):
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(positions)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    vertices = np.hstack([positions, normals]).astype("<f4")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    rows["n"] = 3
    rows["i"] = faces
    path.write_bytes(header.encode("ascii") + vertices.tobytes() + rows.tobytes())


# ---- the scene, for both renderers -----------------------------------------------------------

def write_gltf(path, bin_name, meshes, bsdf_name, case, width, height):
    """meshes: [(name, positions, normals, faces)] in bin_name's order (sphere, floor)."""
    blob, views, accessors, gl_meshes = bytearray(), [], [], []
    for name, pos, nrm, faces in meshes:
        acc = {}
        for key, data, kind, ctype, target in [
            ("POSITION", pos.astype("<f4"), "VEC3", 5126, 34962),
            ("NORMAL", nrm.astype("<f4"), "VEC3", 5126, 34962),
            ("indices", faces.astype("<u4").reshape(-1), "SCALAR", 5125, 34963),
        ]:
            while len(blob) % 4:
                blob.append(0)
            views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": data.nbytes,
                          "target": target})
            blob += data.tobytes()
            a = {"bufferView": len(views) - 1, "componentType": ctype, "type": kind,
                 "count": len(data)}
            if key == "POSITION":
                a["min"], a["max"] = pos.min(0).tolist(), pos.max(0).tolist()
            accessors.append(a)
            acc[key] = len(accessors) - 1
        gl_meshes.append({"name": name, "primitives": [{
            "attributes": {"POSITION": acc["POSITION"], "NORMAL": acc["NORMAL"]},
            "indices": acc["indices"], "material": 0 if name == "sphere" else 1}]})
    (path.parent / bin_name).write_bytes(bytes(blob))
    right, up, forward = camera_basis()
    cam = np.eye(4)
    cam[:3, 0], cam[:3, 1], cam[:3, 2], cam[:3, 3] = right, up, -forward, EYE
    nodes = [{"name": "sphere", "mesh": 0},
             {"name": "light", "translation": LIGHT_POSITION,
              "extensions": {"KHR_lights_punctual": {"light": 0}}},
             {"name": "camera", "camera": 0, "matrix": cam.T.reshape(-1).tolist()}]
    if case["floor"]:
        nodes.append({"name": "floor", "mesh": 1})
    doc = {
        "asset": {"version": "2.0", "generator": "docs/bench/mitsuba_measured.py"},
        "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_specular"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "color": [1.0, 1.0, 1.0], "intensity": LIGHT_INTENSITY}]}},
        "scene": 0,
        "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes,
        "cameras": [{"type": "perspective", "perspective": {
            "yfov": math.radians(YFOV_DEG), "aspectRatio": width / height, "znear": 0.01}}],
        "meshes": gl_meshes,
        "materials": [
            {"name": "sphere", "extras": {"facet": {"model": "measured", "source": bsdf_name}}},
            {"name": "floor", "pbrMetallicRoughness": {
                "baseColorFactor": [FLOOR_ALBEDO] * 3 + [1.0], "metallicFactor": 0.0,
                "roughnessFactor": 1.0},
             "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}},
        ],
        "buffers": [{"uri": bin_name, "byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    path.write_text(json.dumps(doc, indent=1))


def mitsuba_scene(workdir, bsdf_path, case, width, height, spp):
    right, up, forward = camera_basis()
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": case["max_depth"] + 1, "rr_depth": 4},
        "sensor": {
            "type": "perspective", "fov": YFOV_DEG, "fov_axis": "y", "near_clip": 0.01,
            "to_world": T().look_at(origin=EYE.tolist(), target=TARGET.tolist(), up=up.tolist()),
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sphere": {"type": "ply", "filename": str(workdir / "sphere.ply"), "face_normals": False,
                   "bsdf": {"type": "measured", "filename": str(bsdf_path)}},
        "light": {"type": "point", "position": LIGHT_POSITION,
                  "intensity": {"type": "rgb", "value": LIGHT_INTENSITY}},
    }
    if case["floor"]:
        d["floor"] = {"type": "ply", "filename": str(workdir / "floor.ply"), "face_normals": False,
                      "bsdf": {"type": "twosided", "bsdf": {
                          "type": "diffuse", "reflectance": {"type": "rgb", "value": FLOOR_ALBEDO}}}}
    if case["sky"]:
        d["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": SKY}}
    return mi.load_dict(d)


def corner_hits(width, height, radius):
    """Whether the ray through each pixel corner ((height + 1) x (width + 1)) hits the sphere of
    this radius about the origin."""
    right, up, forward = camera_basis()
    t = math.tan(math.radians(YFOV_DEG) / 2)
    xs = (2.0 * np.arange(width + 1) / width - 1.0) * t * width / height
    ys = (1.0 - 2.0 * np.arange(height + 1) / height) * t
    X, Y = np.meshgrid(xs, ys)
    d = forward + X[..., None] * right + Y[..., None] * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    b = d @ EYE
    return b * b - (EYE @ EYE - radius ** 2) > 0


def sphere_masks(width, height):
    """(sphere, silhouette): pixels whose four corner rays all hit the sphere of radius
    MASK_RADIUS (so every sample of the pixel hits the tessellated unit sphere, nearer than the
    floor), and pixels neither that nor clear of the sphere of radius 2 - MASK_RADIUS."""
    def all_any(hit):
        c = [hit[:-1, :-1], hit[1:, :-1], hit[:-1, 1:], hit[1:, 1:]]
        return c[0] & c[1] & c[2] & c[3], c[0] | c[1] | c[2] | c[3]
    inside, _ = all_any(corner_hits(width, height, MASK_RADIUS))
    _, touched = all_any(corner_hits(width, height, 2.0 - MASK_RADIUS))
    return inside, touched & ~inside


# ---- statistics ------------------------------------------------------------------------------

def stats(a, b, mask):
    """Mean of the channel-mean image (a + b) / 2 over mask, and its standard error."""
    ca, cb = a.mean(-1)[mask], b.mean(-1)[mask]
    n = ca.size
    return float((0.5 * (ca + cb)).mean()), float(math.sqrt(((ca - cb) ** 2).sum() / 4.0) / n)


def region_masks(width, height, n=4):
    out = []
    for r in range(n):
        for c in range(n):
            m = np.zeros((height, width), dtype=bool)
            m[r * height // n:(r + 1) * height // n, c * width // n:(c + 1) * width // n] = True
            out.append(m)
    return out


def variance(x, mask=None):
    """Per-pixel variance E[(a - b)^2] / 2 averaged over pixels (and channels), and its standard
    error over pixels (of the channel-mean of each pixel's (a - b)^2 / 2)."""
    d = (0.5 * (x[0] - x[1]) ** 2).mean(-1)
    d = d if mask is None else d[mask]
    return float(d.mean()), float(d.std() / math.sqrt(d.size))


def ratio(x, x_se, y, y_se):
    r = x / y
    return r, r * math.hypot(x_se / x, y_se / y)


def compare(f, m, masks, width, height):
    """Facet's renders f and Mitsuba's m (seeds 0 and 1 each), masks: {name: pixel mask}."""
    def region(rm):
        fm, fs = stats(*f, rm)
        mm, ms = stats(*m, rm)
        se = math.hypot(fs, ms)
        return {"facet": fm, "facet_se": fs, "mitsuba": mm, "mitsuba_se": ms,
                "ratio": fm / mm if mm > 0 else None, "z": (fm - mm) / se if se > 0 else None}
    out = {"regions_4x4": [region(rm) for rm in region_masks(width, height)]}
    everything = np.ones((height, width), dtype=bool)
    for name, rm in [("image", everything), *masks.items()]:
        out[name] = region(rm)
        out[name]["pixels"] = int(rm.sum())
        vf, vf_se = variance(f, rm)
        vm, vm_se = variance(m, rm)
        out[name]["variance_facet"], out[name]["variance_facet_se"] = vf, vf_se
        out[name]["variance_mitsuba"], out[name]["variance_mitsuba_se"] = vm, vm_se
        out[name]["variance_ratio"], out[name]["variance_ratio_se"] = ratio(vf, vf_se, vm, vm_se)
    return out


# ---- rendering -------------------------------------------------------------------------------

def read_exr(path):
    return np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]


def render_facet(args, gltf, case, stem):
    images, seconds, renders = [], [], []
    for seed in [0, 1]:
        out = stem.parent / f"{stem.name}-facet-{seed}.png"
        cmd = [str(args.facet_bin), "render", str(gltf), "--width", str(args.width),
               "--height", str(args.height), "--spp", str(args.spp),
               "--max-depth", str(case["max_depth"]), "--seed", str(seed), "--out", str(out)]
        if case["sky"]:
            cmd += ["--env-color", str(SKY)]
        t = time.perf_counter()
        run = subprocess.run(cmd, capture_output=True, text=True)
        seconds.append(time.perf_counter() - t)
        if run.returncode != 0:
            sys.exit(f"{' '.join(cmd)} failed:\n{run.stdout}{run.stderr}")
        renders.append((run.stdout + run.stderr).strip())
        images.append(read_exr(out.with_suffix(".exr")))
    return images, seconds, cmd, renders


def render_mitsuba(scene, stem, keep):
    images, seconds = [], []
    for seed in [0, 1]:
        t = time.perf_counter()
        img = np.array(mi.render(scene, seed=seed), dtype=np.float64)[..., :3]
        seconds.append(time.perf_counter() - t)
        images.append(img)
        if keep:
            mi.Bitmap(img.astype(np.float32)).write(str(stem.parent / f"{stem.name}-mitsuba-{seed}.exr"))
    return images, seconds


def bsdf_file(facet_bin, name, source, workdir):
    """A .bsdf as is, or `facet convert SOURCE workdir/NAME.bsdf`."""
    if source.endswith(".bsdf") and Path(source).is_file():
        return Path(source).resolve(), None
    out = workdir / f"{name}.bsdf"
    cmd = [str(facet_bin), "convert", source, str(out), "--force"]
    run = subprocess.run(cmd, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{run.stdout}{run.stderr}")
    return out, (run.stdout + run.stderr).strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--facet-bin", type=Path, default=shutil.which("facet") or "facet")
    ap.add_argument("--material", action="append", metavar="NAME=SOURCE",
                    help="a .bsdf file, or any `facet convert` input written to NAME.bsdf "
                         f"(repeatable; default {' '.join(DEFAULT_MATERIALS)})")
    ap.add_argument("--cases", default="direct,full", help="comma-separated: direct, full")
    ap.add_argument("--width", type=int, default=128)
    ap.add_argument("--height", type=int, default=128)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--rings", type=int, default=128, help="UV sphere rings (2x as many segments)")
    ap.add_argument("--workdir", type=Path, default=Path("out/mitsuba-measured"))
    ap.add_argument("--keep-mitsuba-exr", action="store_true")
    ap.add_argument("--json", type=Path, help="write the numbers here")
    args = ap.parse_args()
    args.workdir.mkdir(parents=True, exist_ok=True)
    workdir = args.workdir.resolve()

    sphere, floor = uv_sphere(args.rings), floor_quad()
    write_ply(workdir / "sphere.ply", *sphere)
    write_ply(workdir / "floor.ply", *floor)
    sphere_px, silhouette_px = sphere_masks(args.width, args.height)
    masks = {"sphere": sphere_px, "silhouette": silhouette_px}
    result = {"mitsuba": f"mitsuba {mi.__version__} scalar_rgb path, box filter, independent",
              "command": " ".join(sys.argv),
              "width": args.width, "height": args.height, "spp": args.spp,
              "sphere_triangles": len(sphere[2]), "sphere_pixels": int(sphere_px.sum()),
              "silhouette_pixels": int(silhouette_px.sum()), "runs": []}
    print(f"{result['mitsuba']}; {args.width} x {args.height}, {args.spp} spp, UV sphere of "
          f"{len(sphere[2])} triangles, {int(sphere_px.sum())} sphere-only and "
          f"{int(silhouette_px.sum())} silhouette pixels")
    for spec in args.material or DEFAULT_MATERIALS:
        name, source = spec.split("=", 1)
        bsdf, note = bsdf_file(args.facet_bin, name, source, workdir)
        if note:
            print(note)
        local = workdir / f"{name}.bsdf"
        if bsdf != local:
            shutil.copyfile(bsdf, local)
        for case_name in args.cases.split(","):
            case = CASES[case_name]
            stem = workdir / f"{name}-{case_name}"
            gltf = stem.with_suffix(".gltf")
            meshes = [("sphere", *sphere), ("floor", *floor)]
            write_gltf(gltf, f"{name}-{case_name}.bin", meshes, local.name, case,
                       args.width, args.height)
            f, f_sec, f_cmd, f_log = render_facet(args, gltf, case, stem)
            scene = mitsuba_scene(workdir, local, case, args.width, args.height, args.spp)
            m, m_sec = render_mitsuba(scene, stem, args.keep_mitsuba_exr)
            r = {"material": name, "source": source, "case": case_name, **case,
                 "facet_command": " ".join(f_cmd), "facet_log_seed1": f_log[1],
                 "facet_seconds": f_sec, "facet_render_seconds": [
                     float(m_.group(1)) / 1e3 if (m_ := re.search(r"timings \(ms\):.* render (\d+)", log)) else None
                     for log in f_log],
                 "mitsuba_seconds": m_sec,
                 **compare(f, m, masks, args.width, args.height)}
            result["runs"].append(r)
            report(r)
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")


def fmt(x, digits=4):
    return "-" if x is None else f"{x:.{digits}f}"


def report(r):
    print(f"\n== {r['material']} ({r['source']}), {r['case']}: Facet max_depth {r['max_depth']}, "
          f"floor {r['floor']}, sky {r['sky']}")
    print("region means, 4 x 4, top row first: Facet / Mitsuba (ratio, z)")
    regions = r["regions_4x4"]
    for row in range(4):
        print("  " + "   ".join(
            f"{g['facet']:.4f}/{g['mitsuba']:.4f} ({fmt(g['ratio'], 3)}, {fmt(g['z'], 1)})"
            for g in regions[4 * row:4 * row + 4]))
    for name in ["image", "sphere", "silhouette"]:
        g = r[name]
        print(f"{name} ({g['pixels']} px): mean Facet {g['facet']:.5f} +- {g['facet_se']:.5f}, "
              f"Mitsuba {g['mitsuba']:.5f} +- {g['mitsuba_se']:.5f}: ratio {fmt(g['ratio'])}, "
              f"z {fmt(g['z'], 2)}; variance Facet {g['variance_facet']:.3e}, Mitsuba "
              f"{g['variance_mitsuba']:.3e}: ratio {g['variance_ratio']:.3f} +- "
              f"{g['variance_ratio_se']:.3f}")
    print(f"time a render: Facet {np.mean(r['facet_seconds']):.2f} s (whole process; its render "
          f"stage {np.mean(r['facet_render_seconds']):.2f} s), "
          f"Mitsuba {np.mean(r['mitsuba_seconds']):.2f} s")


if __name__ == "__main__":
    main()
