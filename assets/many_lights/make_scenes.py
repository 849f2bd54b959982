"""The many-light benchmark rooms of issue 49, written as self-contained glTF 2.0 files.

    python3 assets/many_lights/make_scenes.py        # rewrites room_points.gltf, room_panels.gltf

Standard library only; deterministic (a fixed seed, and the same bytes on every run).

Both files share one room, Y up, metres: x in [-5, 5], y in [0, 3], z in [-4, 4]. Floor, ceiling
and walls are single inward-facing quads; a 10 cm partition at x = 1.5 runs from the back wall
(z = -4) to z = 2, with a lintel above the 2 m doorway it leaves (z in [2, 4], y in [2.2, 3]), so
the part x > 1.5 ("the back room") sees its own lamps and, through the doorway, some of the
others. Two boxes (one in each part) and a UV sphere make the image less trivial. Every surface is
Lambertian: metallicFactor 0, roughnessFactor 1 and KHR_materials_specular specularFactor 0 (which
turns off the dielectric F0 = 0.04 lobe Facet otherwise adds), so that Mitsuba's `diffuse` is the
same BSDF (docs/bench/mitsuba_many_lights.py).

- room_points.gltf: 100 KHR_lights_punctual lights in a jittered 10 x 10 grid 20 cm below the
  ceiling, about half points and half spots; the spots aim down, tilted by up to 20 degrees,
  outer cone 35-65 degrees, inner cone 50-80 % of it. Intensities (candela, which Facet and
  Mitsuba both read as W/sr) are log-uniform over a factor of 10, so that selecting lights by
  power and by importance differ.
- room_panels.gltf: the same room with each lamp replaced by a square emissive panel 1 cm below
  the ceiling, facing down (one-sided emitters emit from their counter-clockwise side), each a
  10 x 5 grid of quads = 100 triangles, so 10,000 emissive triangles in all. A panel emits the
  same power as the lamp it replaces: Phi = 4 pi I for a point, Phi = 2 pi I ((1 - cos_i) +
  (cos_i - cos_o) / 3) for a glTF spot (its falloff t^2, t linear in cos theta), and a Lambertian
  panel of area A and radiance L emits Phi = pi A L. All panels share one set of accessors (one
  panel in local space, placed and scaled by its node), which keeps the file small.

The camera `main` (camera 0, on node `camera`) stands in the front-left corner looking at the
partition and the doorway: most of the back room's lamps are hidden from what it sees.
"""

import base64
import json
import math
import random
import struct
from pathlib import Path

SEED = 49
ROOM = ((-5.0, 0.0, -4.0), (5.0, 3.0, 4.0))
PARTITION_X = 1.5
PARTITION_HALF_THICKNESS = 0.05
DOOR_Z = 2.0
LINTEL_Y = 2.2
LAMP_Y = 2.8
PANEL_Y = 2.99
GRID = (10, 10)
# Power-equivalent exposure: lit floor radiance about 0.3-0.6 at Facet's --exposure 0.
POINT_INTENSITY = (0.1, 1.0)
SPOT_INTENSITY = (0.25, 2.5)
PANEL_QUADS = (10, 5)


# ---- small vector helpers ------------------------------------------------------------------

def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def normalize(a):
    n = math.sqrt(dot(a, a))
    return tuple(x / n for x in a)


def f32(x):
    """x rounded to the f32 the buffer will hold (so accessor min/max match the data)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def quat_from_arc(a, b):
    """The unit quaternion (x, y, z, w) rotating unit vector a onto unit vector b (a != -b)."""
    c = cross(a, b)
    q = (c[0], c[1], c[2], 1.0 + dot(a, b))
    n = math.sqrt(dot(q, q))
    return [x / n for x in q]


def quat_from_frame(right, up, back):
    """The unit quaternion of the rotation matrix with columns (right, up, back)."""
    m = [[right[i], up[i], back[i]] for i in range(3)]
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0.0:
        s = 2.0 * math.sqrt(tr + 1.0)
        q = ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    else:
        i = max(range(3), key=lambda k: m[k][k])
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
        v = [0.0, 0.0, 0.0]
        v[i] = 0.25 * s
        v[j] = (m[j][i] + m[i][j]) / s
        v[k] = (m[k][i] + m[i][k]) / s
        q = (v[0], v[1], v[2], (m[k][j] - m[j][k]) / s)
    n = math.sqrt(dot(q, q))
    return [x / n for x in q]


# ---- glTF writer ---------------------------------------------------------------------------

class Gltf:
    """Accumulates one binary buffer, accessors, meshes, materials, nodes, lights."""

    def __init__(self):
        self.bin = bytearray()
        self.doc = {
            "asset": {"version": "2.0", "generator": "facet assets/many_lights/make_scenes.py"},
            "scene": 0,
            "scenes": [{"nodes": []}],
            "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [],
            "cameras": [],
        }
        self.lights = []

    def _view(self, data, target):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["bufferViews"].append(
            {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data), "target": target})
        self.bin.extend(data)
        return len(self.doc["bufferViews"]) - 1

    def vec3s(self, vs, with_bounds=False):
        flat = [f32(x) for v in vs for x in v]
        view = self._view(struct.pack(f"<{len(flat)}f", *flat), 34962)
        acc = {"bufferView": view, "componentType": 5126, "count": len(vs), "type": "VEC3"}
        if with_bounds:
            acc["min"] = [min(flat[i::3]) for i in range(3)]
            acc["max"] = [max(flat[i::3]) for i in range(3)]
        self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def indices(self, idx):
        big = max(idx) > 65535
        data = struct.pack(f"<{len(idx)}{'I' if big else 'H'}", *idx)
        view = self._view(data, 34963)
        self.doc["accessors"].append({"bufferView": view, "componentType": 5125 if big else 5123,
                                      "count": len(idx), "type": "SCALAR"})
        return len(self.doc["accessors"]) - 1

    def geometry(self, positions, normals, idx):
        """Accessors of one primitive: (POSITION, NORMAL, indices)."""
        return (self.vec3s(positions, True), self.vec3s(normals), self.indices(idx))

    def material(self, name, base, emissive=None):
        m = {"name": name,
             "pbrMetallicRoughness": {"baseColorFactor": [*base, 1.0], "metallicFactor": 0.0,
                                      "roughnessFactor": 1.0},
             "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}
        if emissive is not None:
            # emissiveFactor <= 1 carries the colour, the strength the rest.
            peak = max(emissive)
            m["emissiveFactor"] = [c / peak for c in emissive]
            if peak != 1.0:
                m["extensions"]["KHR_materials_emissive_strength"] = {"emissiveStrength": peak}
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, name, geometry, material):
        pos, nrm, idx = geometry
        self.doc["meshes"].append({"name": name, "primitives": [{
            "attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx,
            "material": material, "mode": 4}]})
        return len(self.doc["meshes"]) - 1

    def node(self, node):
        self.doc["nodes"].append(node)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["nodes"]) - 1

    def light(self, name, light, translation, rotation=None):
        self.lights.append({"name": name, **light})
        node = {"name": name, "translation": translation,
                "extensions": {"KHR_lights_punctual": {"light": len(self.lights) - 1}}}
        if rotation is not None:
            node["rotation"] = rotation
        self.node(node)

    def write(self, path):
        doc = dict(self.doc)
        used = {"KHR_materials_specular"}
        if any("KHR_materials_emissive_strength" in m.get("extensions", {})
               for m in doc["materials"]):
            used.add("KHR_materials_emissive_strength")
        if self.lights:
            doc["extensions"] = {"KHR_lights_punctual": {"lights": self.lights}}
            used.add("KHR_lights_punctual")
        doc["extensionsUsed"] = sorted(used)
        doc["buffers"] = [{"byteLength": len(self.bin), "uri":
                           "data:application/octet-stream;base64,"
                           + base64.b64encode(bytes(self.bin)).decode("ascii")}]
        path.write_text(json.dumps(doc, indent=1) + "\n")


# ---- geometry ------------------------------------------------------------------------------

def quad(corners, normal):
    """Four corners counter-clockwise seen from where `normal` points: two triangles."""
    (a, b, c, _) = corners
    assert dot(cross(sub(b, a), sub(c, a)), normal) > 0.0, "quad wound clockwise"
    return list(corners), [normal] * 4, [0, 1, 2, 0, 2, 3]


def box(lo, hi):
    """An axis-aligned box, outward normals, 24 vertices (flat faces), 12 triangles."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    faces = [
        ([(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)], (1, 0, 0)),
        ([(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)], (-1, 0, 0)),
        ([(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)], (0, 1, 0)),
        ([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], (0, -1, 0)),
        ([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], (0, 0, 1)),
        ([(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)], (0, 0, -1)),
    ]
    return merge([quad(c, n) for c, n in faces])


def merge(parts):
    """Concatenates (positions, normals, indices) triples."""
    p, n, idx = [], [], []
    for pp, nn, ii in parts:
        idx.extend(i + len(p) for i in ii)
        p.extend(pp)
        n.extend(nn)
    return p, n, idx


def uv_sphere(centre, r, segments=32, rings=16):
    """A UV sphere, counter-clockwise from outside; one triangle per segment at the poles."""
    p, n = [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            d = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            p.append(tuple(c + r * x for c, x in zip(centre, d)))
            n.append(d)
    row = segments + 1
    idx = []

    def tri(a, b, c):
        # Keep the triangle counter-clockwise seen from outside.
        g = cross(sub(p[b], p[a]), sub(p[c], p[a]))
        out = sub(p[a], centre)
        idx.extend([a, b, c] if dot(g, out) > 0.0 else [a, c, b])

    for i in range(rings):
        for j in range(segments):
            a, b = i * row + j, i * row + j + 1
            c, d = a + row, b + row
            if i != 0:
                tri(a, c, b)
            if i != rings - 1:
                tri(b, c, d)
    return p, n, idx


def panel(nx, nz):
    """A unit square in the y = 0 plane centred at the origin, facing -Y, nx x nz quads."""
    p = [(-0.5 + i / nx, 0.0, -0.5 + k / nz) for k in range(nz + 1) for i in range(nx + 1)]
    n = [(0.0, -1.0, 0.0)] * len(p)
    idx = []
    for k in range(nz):
        for i in range(nx):
            a = k * (nx + 1) + i
            b, c, d = a + 1, a + nx + 1, a + nx + 2
            # (a, b, d) runs +x then +z: seen from below (-Y) that is counter-clockwise.
            idx.extend([a, b, d, a, d, c])
    assert dot(cross(sub(p[1], p[0]), sub(p[nx + 2], p[0])), (0, -1, 0)) > 0.0
    return p, n, idx


# ---- the room ------------------------------------------------------------------------------

def add_room(g):
    """Room, partition, lintel, boxes, sphere and the camera; returns nothing."""
    (x0, y0, z0), (x1, y1, z1) = ROOM
    grey = g.material("wall", (0.6, 0.6, 0.6))
    floor = g.material("floor", (0.45, 0.42, 0.38))
    ceiling = g.material("ceiling", (0.75, 0.75, 0.75))
    red = g.material("red_wall", (0.62, 0.18, 0.14))
    partition = g.material("partition", (0.55, 0.6, 0.65))
    box_a = g.material("box_blue", (0.2, 0.3, 0.6))
    box_b = g.material("box_green", (0.25, 0.5, 0.2))
    sphere = g.material("sphere", (0.7, 0.65, 0.5))

    surfaces = [
        ("floor", floor, quad([(x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0)], (0, 1, 0))),
        ("ceiling", ceiling,
         quad([(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)], (0, -1, 0))),
        ("wall_left", grey,
         quad([(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)], (1, 0, 0))),
        ("wall_right", grey,
         quad([(x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0)], (-1, 0, 0))),
        ("wall_back", red,
         quad([(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)], (0, 0, 1))),
        ("wall_front", grey,
         quad([(x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1)], (0, 0, -1))),
        ("partition", partition,
         merge([box((PARTITION_X - PARTITION_HALF_THICKNESS, y0, z0),
                    (PARTITION_X + PARTITION_HALF_THICKNESS, y1, DOOR_Z)),
                box((PARTITION_X - PARTITION_HALF_THICKNESS, LINTEL_Y, DOOR_Z),
                    (PARTITION_X + PARTITION_HALF_THICKNESS, y1, z1))])),
        ("box_front", box_a, box((-2.6, 0.0, -0.4), (-1.6, 0.8, 0.6))),
        ("box_back", box_b, box((3.0, 0.0, 2.4), (3.7, 1.4, 3.1))),
        ("sphere", sphere, uv_sphere((-0.6, 0.55, 2.0), 0.55)),
    ]
    for name, mat, geo in surfaces:
        g.node({"name": name, "mesh": g.mesh(name, g.geometry(*geo), mat)})

    # Camera in the front-left corner, looking at the partition and the doorway beside it.
    eye = (-4.3, 1.6, 3.5)
    target = (1.5, 1.1, -0.2)
    forward = normalize(sub(target, eye))
    right = normalize(cross(forward, (0.0, 1.0, 0.0)))
    up = cross(right, forward)
    g.doc["cameras"].append({"name": "main", "type": "perspective", "perspective": {
        "yfov": math.radians(55.0), "aspectRatio": 16.0 / 9.0, "znear": 0.05, "zfar": 100.0}})
    g.node({"name": "camera", "camera": 0, "translation": list(eye),
            "rotation": quat_from_frame(right, up, tuple(-x for x in forward))})


def lamps():
    """The 100 lamps: a jittered 10 x 10 grid below the ceiling, each a point or a spot.

    Returns dicts with name, position, kind, colour, intensity (cd), and for spots direction,
    inner and outer cone (radians). Lamps are kept 25 cm clear of the partition's plane.
    """
    rng = random.Random(SEED)
    (x0, _, z0), (x1, _, z1) = ROOM
    nx, nz = GRID
    cw, cd = (x1 - x0) / nx, (z1 - z0) / nz
    out = []
    for k in range(nz):
        for i in range(nx):
            x = x0 + (i + 0.5 + 0.5 * (rng.random() - 0.5)) * cw
            z = z0 + (k + 0.5 + 0.5 * (rng.random() - 0.5)) * cd
            if abs(x - PARTITION_X) < 0.25:
                x = PARTITION_X + math.copysign(0.25, x - PARTITION_X)
            # Colour temperature between warm and cool white, peak channel 1.
            w = rng.random()
            colour = (1.0, 0.82 + 0.18 * w, 0.62 + 0.38 * w)
            spot = rng.random() < 0.5
            lo, hi = SPOT_INTENSITY if spot else POINT_INTENSITY
            intensity = lo * (hi / lo) ** rng.random()
            lamp = {"name": f"{'spot' if spot else 'point'}_{len(out):02d}",
                    "position": (x, LAMP_Y, z), "kind": "spot" if spot else "point",
                    "colour": colour, "intensity": intensity}
            if spot:
                tilt = math.radians(20.0) * rng.random()
                azimuth = 2.0 * math.pi * rng.random()
                lamp["direction"] = (math.sin(tilt) * math.cos(azimuth), -math.cos(tilt),
                                     math.sin(tilt) * math.sin(azimuth))
                outer = math.radians(35.0 + 30.0 * rng.random())
                lamp["outer"] = outer
                lamp["inner"] = outer * (0.5 + 0.3 * rng.random())
            out.append(lamp)
    return out


def lamp_power(lamp):
    """Radiant power of a lamp per unit colour: 4 pi I, or the glTF spot's
    2 pi I integral of t(cos)^2 over cos in [cos_o, 1] = 2 pi I ((1 - ci) + (ci - co) / 3)."""
    if lamp["kind"] == "point":
        return 4.0 * math.pi * lamp["intensity"]
    ci, co = math.cos(lamp["inner"]), math.cos(lamp["outer"])
    return 2.0 * math.pi * lamp["intensity"] * ((1.0 - ci) + (ci - co) / 3.0)


def write_points(path, lamp_list):
    g = Gltf()
    add_room(g)
    for lamp in lamp_list:
        light = {"type": lamp["kind"], "color": list(lamp["colour"]), "intensity": lamp["intensity"]}
        rotation = None
        if lamp["kind"] == "spot":
            light["spot"] = {"innerConeAngle": lamp["inner"], "outerConeAngle": lamp["outer"]}
            # glTF spots shine along the node's -Z.
            rotation = quat_from_arc((0.0, 0.0, -1.0), lamp["direction"])
        g.light(lamp["name"], light, list(lamp["position"]), rotation)
    g.write(path)


def write_panels(path, lamp_list):
    g = Gltf()
    add_room(g)
    geometry = g.geometry(*panel(*PANEL_QUADS))
    rng = random.Random(SEED + 1)
    for lamp in lamp_list:
        side = 0.2 + 0.16 * rng.random()
        # pi A L = Phi  =>  L = Phi / (pi A), per colour channel.
        radiance = lamp_power(lamp) / (math.pi * side * side)
        name = "panel" + lamp["name"][lamp["name"].index("_"):]
        mat = g.material(name, (0.8, 0.8, 0.8), tuple(radiance * c for c in lamp["colour"]))
        x, _, z = lamp["position"]
        g.node({"name": name, "mesh": g.mesh(name, geometry, mat),
                "translation": [x, PANEL_Y, z], "scale": [side, 1.0, side]})
    g.write(path)


def main():
    here = Path(__file__).resolve().parent
    lamp_list = lamps()
    write_points(here / "room_points.gltf", lamp_list)
    write_panels(here / "room_panels.gltf", lamp_list)
    spots = sum(lamp["kind"] == "spot" for lamp in lamp_list)
    behind = sum(lamp["position"][0] > PARTITION_X for lamp in lamp_list)
    power = sum(lamp_power(lamp) for lamp in lamp_list)
    print(f"{len(lamp_list)} lamps ({len(lamp_list) - spots} points, {spots} spots; "
          f"{behind} behind the partition), {power:.1f} W per unit colour in all")
    for name in ["room_points.gltf", "room_panels.gltf"]:
        print(f"{name}: {(here / name).stat().st_size} bytes")


if __name__ == "__main__":
    main()
