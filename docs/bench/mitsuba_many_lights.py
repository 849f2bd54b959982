"""Issue 49's many-light room in Mitsuba 3, for the side-by-side comparison with `facet render`:
the glTF file itself (assets/many_lights/room_points.gltf by default; room_panels.gltf works
too) is converted here, so both renderers see the same triangles, materials, lights and camera.

    pip install mitsuba==3.9.1 && python3 docs/bench/mitsuba_many_lights.py --json out.json
    facet render assets/many_lights/room_points.gltf --width 256 --height 144 --spp 16 --out f0.png
    facet render ... --seed 1 --out f1.png
    python3 docs/bench/mitsuba_many_lights.py --facet f0.exr f1.exr     # region-wise means too

Conventions, as docs/bench/mitsuba_gold.py: Facet's max_depth counts bounces after the camera
ray, Mitsuba's path vertices, so Mitsuba's is Facet's + 1, and so is rr_depth (Facet plays
Russian roulette from depth 3: Mitsuba's rr_depth 4); the pixel filter is a box, as Facet's.
Per-pixel variance is E[(a - b)^2] / 2 over two renders with seeds 0 and 1, averaged over pixels
and channels; the image mean is that of (a + b) / 2.

The conversion (only what the many-light rooms use):
- every triangle primitive, placed by its node's world matrix (`matrix` or T R S), written as a
  PLY file (positions, normals; winding flipped under a mirroring transform);
- materials: Facet's surfaces are two-sided, Mitsuba's `diffuse` is not: each is a `twosided`
  `diffuse` of baseColorFactor. That is Facet's BSDF only with KHR_materials_specular
  specularFactor 0 (which the rooms set; otherwise Facet adds an F0 = 0.04 GGX lobe: warned);
- emissive materials: an `area` emitter of radiance emissiveFactor x emissiveStrength, one-sided
  on both (Facet's and Mitsuba's emit from the counter-clockwise side);
- KHR_lights_punctual: `intensity x color` is Facet's radiant intensity (candela read as W/sr,
  crates/render/src/scene/gltf_file.rs), Mitsuba's `point` and `spot` intensity is W/sr: the
  same numbers. glTF spots fall off as t^2, t = clamp((cos - cos_o) / (cos_i - cos_o), 0, 1)
  (Facet's shader does exactly that); Mitsuba's `spot` ramps linearly in the angle from
  beam_width to cutoff_angle. With --spot-falloff gltf (the default) each spot gets
  cutoff_angle = beam_width = the outer cone (no ramp) and a projected `texture` holding the glTF
  falloff, sampled at 512 x 512 with bilinear filtering (checked against the formula at start-up:
  the largest difference is printed); --spot-falloff mitsuba maps inner to beam_width and outer
  to cutoff_angle instead, a different (brighter) falloff;
- the camera: the first node with a perspective camera (or --camera, by index or name),
  position = the node's origin, forward = its -Z, up = its +Y, yfov as the vertical fov.

Light selection differs, and that is what the comparison measures: Mitsuba's next-event
estimation picks an emitter uniformly (every `sampling_weight` is the default 1: each point, each
spot, each panel's PLY shape), then a point on it by area; Facet picks by its
--light-selection strategy. The means must agree; the variances say what selection buys.
"""
import argparse
import base64
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
from mitsuba import ScalarTransform4f as T  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SPOT_TEXTURE_SIDE = 512


# ---- glTF reading ----------------------------------------------------------------------------

def load_buffers(path, doc):
    out = []
    for b in doc["buffers"]:
        uri = b["uri"]
        if uri.startswith("data:"):
            out.append(base64.b64decode(uri.split(",", 1)[1]))
        else:
            out.append((path.parent / uri).read_bytes())
    return out


COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
DTYPES = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}


def read_accessor(doc, buffers, index):
    """An accessor as an (count, components) array (no sparse accessors: the rooms have none)."""
    a = doc["accessors"][index]
    view = doc["bufferViews"][a["bufferView"]]
    dtype = np.dtype(DTYPES[a["componentType"]])
    n = COMPONENTS[a["type"]]
    start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
    stride = view.get("byteStride", dtype.itemsize * n)
    raw = np.frombuffer(buffers[view["buffer"]], dtype=np.uint8,
                        count=(a["count"] - 1) * stride + dtype.itemsize * n, offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, (a["count"], dtype.itemsize * n), (stride, 1))
    return rows.copy().view(dtype).reshape(a["count"], n)


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def local_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major
    m = np.eye(4)
    m[:3, :3] = quat_matrix(node.get("rotation", [0, 0, 0, 1])) @ np.diag(node.get("scale", [1, 1, 1]))
    m[:3, 3] = node.get("translation", [0, 0, 0])
    return m


def placed_nodes(doc):
    """(node, world matrix) of the default scene, parents first, as Facet walks it."""
    scene = doc["scenes"][doc.get("scene", 0)]
    stack = [(i, np.eye(4)) for i in reversed(scene["nodes"])]
    out = []
    while stack:
        i, parent = stack.pop()
        node = doc["nodes"][i]
        world = parent @ local_matrix(node)
        out.append((node, world))
        stack.extend((c, world) for c in reversed(node.get("children", [])))
    return out


# ---- conversion ------------------------------------------------------------------------------

def write_ply(path, positions, normals, faces):
    header = ("ply\nformat binary_little_endian 1.0\n"
              f"element vertex {len(positions)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    vertices = np.hstack([positions, normals]).astype("<f4")
    face_rows = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face_rows["n"] = 3
    face_rows["i"] = faces
    path.write_bytes(header.encode("ascii") + vertices.tobytes() + face_rows.tobytes())


def gltf_spot_falloff(cos_theta, cos_inner, cos_outer):
    """glTF / Facet: t^2, t = clamp((cos - cos_o) / (cos_i - cos_o), 0, 1)."""
    t = np.clip((cos_theta - cos_outer) / max(cos_inner - cos_outer, 1e-4), 0.0, 1.0)
    return t * t


def spot_texture(inner, outer):
    """The glTF falloff as Mitsuba's spot projects its texture: texel (u, v) is the direction
    ((2u - 1) tan(outer), (2v - 1) tan(outer), 1) in the light's frame."""
    n = SPOT_TEXTURE_SIDE
    s = (2.0 * (np.arange(n) + 0.5) / n - 1.0) * math.tan(outer)
    x, y = np.meshgrid(s, s)
    cos_theta = 1.0 / np.sqrt(1.0 + x * x + y * y)
    values = gltf_spot_falloff(cos_theta, math.cos(inner), math.cos(outer))
    return {"type": "bitmap", "bitmap": mi.Bitmap(values.astype(np.float32)[..., None]),
            "raw": True, "filter_type": "bilinear"}


def convert(gltf_path, camera_wanted, spot_falloff, workdir):
    """The scene's Mitsuba dict entries (shapes and emitters), counts, spot cones and camera."""
    doc = json.loads(gltf_path.read_text())
    buffers = load_buffers(gltf_path, doc)
    materials = doc.get("materials", [])
    for m in materials:
        spec = m.get("extensions", {}).get("KHR_materials_specular", {}).get("specularFactor", 1.0)
        if spec != 0.0 or m.get("pbrMetallicRoughness", {}).get("metallicFactor", 1.0) != 0.0:
            print(f"warning: material {m.get('name')} is not Lambertian in Facet "
                  "(specularFactor or metallicFactor not 0); Mitsuba renders it diffuse",
                  file=sys.stderr)
    lights = doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    entries, counts = {}, {"triangles": 0, "emissive_triangles": 0, "points": 0, "spots": 0}
    cones = []  # (entry key, position, unit direction, inner, outer) of every spot
    camera = None
    for k, (node, world) in enumerate(placed_nodes(doc)):
        m3 = world[:3, :3]
        if "mesh" in node:
            normal_matrix = np.linalg.inv(m3).T
            for p, prim in enumerate(doc["meshes"][node["mesh"]]["primitives"]):
                if prim.get("mode", 4) != 4:
                    continue
                pos = read_accessor(doc, buffers, prim["attributes"]["POSITION"]).astype(np.float64)
                nrm = read_accessor(doc, buffers, prim["attributes"]["NORMAL"]).astype(np.float64)
                faces = read_accessor(doc, buffers, prim["indices"]).reshape(-1, 3).astype(np.int32)
                pos = pos @ m3.T + world[:3, 3]
                nrm = nrm @ normal_matrix.T
                nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
                if np.linalg.det(m3) < 0:
                    faces = faces[:, [0, 2, 1]]
                ply = workdir / f"shape_{k}_{p}.ply"
                write_ply(ply, pos, nrm, faces)
                mat = materials[prim["material"]] if "material" in prim else {}
                base = mat.get("pbrMetallicRoughness", {}).get("baseColorFactor", [1, 1, 1, 1])[:3]
                shape = {"type": "ply", "filename": str(ply), "face_normals": False,
                         "bsdf": {"type": "twosided", "bsdf": {
                             "type": "diffuse", "reflectance": {"type": "rgb", "value": base}}}}
                strength = mat.get("extensions", {}).get(
                    "KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
                emissive = [c * strength for c in mat.get("emissiveFactor", [0, 0, 0])]
                counts["triangles"] += len(faces)
                if max(emissive) > 0.0:
                    shape["emitter"] = {"type": "area",
                                        "radiance": {"type": "rgb", "value": emissive}}
                    counts["emissive_triangles"] += len(faces)
                entries[f"shape_{k}_{p}"] = shape
        if "KHR_lights_punctual" in node.get("extensions", {}):
            light = lights[node["extensions"]["KHR_lights_punctual"]["light"]]
            intensity = [c * light.get("intensity", 1.0) for c in light.get("color", [1, 1, 1])]
            position = world[:3, 3].tolist()
            if light["type"] == "point":
                entries[f"light_{k}"] = {"type": "point", "position": position,
                                         "intensity": {"type": "rgb", "value": intensity}}
                counts["points"] += 1
            elif light["type"] == "spot":
                direction = -m3[:, 2] / np.linalg.norm(m3[:, 2])  # the node's -Z
                helper = [1, 0, 0] if abs(direction[1]) > 0.9 else [0, 1, 0]
                inner = light["spot"].get("innerConeAngle", 0.0)
                outer = light["spot"].get("outerConeAngle", math.pi / 4)
                spot = {"type": "spot", "intensity": {"type": "rgb", "value": intensity},
                        "to_world": T().look_at(origin=position,
                                                target=(world[:3, 3] + direction).tolist(),
                                                up=helper)}
                if spot_falloff == "gltf":
                    spot.update(cutoff_angle=math.degrees(outer), beam_width=math.degrees(outer),
                                texture=spot_texture(inner, outer))
                else:
                    spot.update(cutoff_angle=math.degrees(outer), beam_width=math.degrees(inner))
                entries[f"light_{k}"] = spot
                cones.append((f"light_{k}", world[:3, 3], direction, inner, outer))
                counts["spots"] += 1
            else:
                print(f"warning: {light['type']} light skipped", file=sys.stderr)
        if "camera" in node:
            cam = doc["cameras"][node["camera"]]
            wanted = camera_wanted is None or camera_wanted in (str(node["camera"]), cam.get("name"))
            if camera is None and wanted and cam.get("type") == "perspective":
                camera = (cam, world)
    if camera is None:
        sys.exit(f"{gltf_path}: no perspective camera" + (f" `{camera_wanted}`" if camera_wanted else ""))
    return entries, counts, cones, camera


# ---- rendering -------------------------------------------------------------------------------

def mitsuba_scene(entries, camera, width, height, spp, max_depth, rr_depth):
    cam, world = camera
    eye = world[:3, 3]
    forward = -world[:3, 2] / np.linalg.norm(world[:3, 2])
    up = world[:3, 1] / np.linalg.norm(world[:3, 1])
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth + 1, "rr_depth": rr_depth + 1},
        "sensor": {
            "type": "perspective",
            "fov": math.degrees(cam["perspective"]["yfov"]),
            "fov_axis": "y",
            "near_clip": cam["perspective"].get("znear", 0.01),
            "to_world": T().look_at(origin=eye.tolist(), target=(eye + forward).tolist(),
                                    up=up.tolist()),
            "film": {"type": "hdrfilm", "width": width, "height": height,
                     "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        **entries,
    })


def region_means(img, rows=3, cols=4):
    h, w = img.shape[:2]
    return np.array([[img[r * h // rows:(r + 1) * h // rows, c * w // cols:(c + 1) * w // cols].mean()
                      for c in range(cols)] for r in range(rows)])


def read_exr(path):
    return np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", nargs="?", type=Path,
                    default=ROOT / "assets/many_lights/room_points.gltf")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--height", type=int, default=144)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--max-depth", type=int, default=5, help="Facet's: bounces after the camera ray")
    ap.add_argument("--rr-depth", type=int, default=3, help="Facet's depth where roulette starts")
    ap.add_argument("--camera", help="camera index or name (default: the first perspective one)")
    ap.add_argument("--spot-falloff", choices=["gltf", "mitsuba"], default="gltf")
    ap.add_argument("--json", type=Path, help="write the numbers here")
    ap.add_argument("--exr", type=Path, help="write Mitsuba's seed-0 render here")
    ap.add_argument("--facet", type=Path, nargs="+", metavar="EXR",
                    help="Facet's render(s) of the same size (two with different seeds: "
                         "its variance too): region-wise means side by side")
    args = ap.parse_args()

    with tempfile.TemporaryDirectory() as tmp:
        entries, counts, cones, camera = convert(args.scene, args.camera, args.spot_falloff, Path(tmp))
        scene = mitsuba_scene(entries, camera, args.width, args.height, args.spp,
                              args.max_depth, args.rr_depth)
        spot_error = check_spots(entries, cones) if args.spot_falloff == "gltf" and cones else None
        images, seconds = [], 0.0
        for seed in [0, 1]:
            t = time.perf_counter()
            images.append(np.array(mi.render(scene, seed=seed), dtype=np.float64)[..., :3])
            seconds += time.perf_counter() - t
    a, b = images
    if args.exr:
        mi.Bitmap(a.astype(np.float32)).write(str(args.exr))
    result = {
        "renderer": f"mitsuba {mi.__version__} scalar_rgb path",
        "scene": args.scene.name,
        **counts,
        "width": args.width, "height": args.height, "spp": args.spp,
        "max_depth_facet": args.max_depth, "rr_depth_facet": args.rr_depth,
        "spot_falloff": args.spot_falloff,
        "mean": float(np.mean(0.5 * (a + b))),
        "variance": float(np.mean(0.5 * (a - b) ** 2)),
        "seconds_per_render": seconds / 2,
    }
    if spot_error is not None:
        result["spot_texture_max_error"] = spot_error
    print(f"{result['renderer']}, {args.scene.name}: {counts['triangles']} triangles "
          f"({counts['emissive_triangles']} emissive), {counts['points']} point and "
          f"{counts['spots']} spot lights; {args.width} x {args.height}, {args.spp} spp, "
          f"Facet max_depth {args.max_depth}")
    if spot_error is not None:
        print(f"spot falloff: glTF's t^2 through a {SPOT_TEXTURE_SIDE}^2 texture, largest error "
              f"{spot_error:.2e} of the peak intensity")
    print(f"mean {result['mean']:.4f}, variance {result['variance']:.4e}, "
          f"{result['seconds_per_render']:.2f} s a render")

    if args.facet:
        facet = [read_exr(p) for p in args.facet]
        if facet[0].shape != a.shape:
            sys.exit(f"{args.facet[0]} is {facet[0].shape[1]} x {facet[0].shape[0]}, "
                     f"Mitsuba's render {args.width} x {args.height}")
        f_mean = facet[0] if len(facet) == 1 else 0.5 * (facet[0] + facet[1])
        m_regions, f_regions = region_means(0.5 * (a + b)), region_means(f_mean)
        print("region means (3 x 4 blocks, top row first): Mitsuba / Facet (ratio)")
        for mr, fr in zip(m_regions, f_regions):
            print("  " + "   ".join(f"{m:.3f} / {f:.3f} ({f / m:.3f})" for m, f in zip(mr, fr)))
        result["facet_mean"] = float(f_mean.mean())
        result["regions_mitsuba"] = m_regions.tolist()
        result["regions_facet"] = f_regions.tolist()
        print(f"Facet mean {result['facet_mean']:.4f} (ratio to Mitsuba's "
              f"{result['facet_mean'] / result['mean']:.4f})")
        if len(facet) >= 2:
            result["facet_variance"] = float(np.mean(0.5 * (facet[0] - facet[1]) ** 2))
            print(f"Facet variance {result['facet_variance']:.4e} "
                  f"({result['facet_variance'] / result['variance']:.3f} x Mitsuba's)")
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")


def check_spots(entries, cones):
    """The largest |Mitsuba's textured spot - glTF falloff| over directions out to 1.05 x each
    spot's outer cone, as a fraction of its peak: Mitsuba's own emitter (sample_direction at
    distance 1) against the formula."""
    worst = 0.0
    rng = np.random.default_rng(0)
    for key, origin, axis, inner, outer in cones:
        emitter = mi.load_dict({**entries[key], "intensity": {"type": "rgb", "value": 1.0}})
        helper = np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        u = np.cross(axis, helper)
        u /= np.linalg.norm(u)
        v = np.cross(axis, u)
        for _ in range(64):
            theta = 1.05 * outer * rng.random()
            phi = 2.0 * math.pi * rng.random()
            d = math.cos(theta) * axis + math.sin(theta) * (math.cos(phi) * u + math.sin(phi) * v)
            it = mi.Interaction3f()
            it.p = mi.Point3f(*(origin + d))
            _, value = emitter.sample_direction(it, mi.Point2f(0.5, 0.5))
            want = gltf_spot_falloff(math.cos(theta), math.cos(inner), math.cos(outer))
            worst = max(worst, abs(float(value[0]) - float(want)))
    return worst


if __name__ == "__main__":
    main()
