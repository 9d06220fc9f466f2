#!/usr/bin/env python3
"""make_scale_scenes.py -- the big scenes of `make bench`'s scale rows (issue 42),
written with the Python standard library alone into a folder under build/:

  unique-1m.gltf     1M unique triangles: small spheres scattered in a room
  unique-10m.gltf    10M unique triangles, the same way
  inst-100.gltf      one 100k-triangle mesh in 100 nodes (10M instanced triangles)
  inst-1000.gltf     the same mesh in 1,000 nodes (100M instanced triangles)
  inst-1000-gpu.gltf the 1,000 copies as one node's EXT_mesh_gpu_instancing

Each is a 20 x 4 x 20 m room (floor, walls, ceiling) lit by an emissive ceiling
panel, with a camera inside. Sphere meshes hold 100 spheres each and are used
once (nothing to instance); the instanced mesh is a bumpy sphere, turned and
scaled per node. Deterministic (a fixed-seed generator), so every run writes
the same bytes. usage: make_scale_scenes.py OUTDIR [NAME ...]
"""
import array
import json
import math
import os
import random
import sys

ROOM = (20.0, 4.0, 20.0)


def uv_sphere(stacks, slices, bump=0.0):
    """Unit sphere: positions, normals (flat lists) and triangle indices.
    With bump the radius wobbles, so normals and areas vary."""
    pos, nrm, idx = [], [], []
    for i in range(stacks + 1):
        th = math.pi * i / stacks
        for j in range(slices + 1):
            ph = 2 * math.pi * j / slices
            d = (math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph))
            r = 1.0 + bump * math.sin(7 * th) * math.sin(5 * ph)
            pos += [r * d[0], r * d[1], r * d[2]]
            nrm += list(d)
    w = slices + 1
    for i in range(stacks):
        for j in range(slices):
            a, b, c, e = i * w + j, i * w + j + 1, (i + 1) * w + j, (i + 1) * w + j + 1
            if i > 0:
                idx += [a, b, c]  # counter-clockwise seen from outside
            if i < stacks - 1:
                idx += [b, e, c]
    return pos, nrm, idx


class Writer:
    """Accumulates the glTF JSON and one binary buffer."""

    def __init__(self, name):
        self.name = name
        self.bin = bytearray()
        self.g = {"asset": {"version": "2.0", "generator": "Ajar make_scale_scenes.py"}, "scene": 0,
                  "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "accessors": [], "bufferViews": [],
                  "materials": [
                      {"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1],
                                                                "metallicFactor": 0, "roughnessFactor": 1}},
                      {"name": "lamp", "emissiveFactor": [1, 1, 1],
                       "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 20}},
                       "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1], "metallicFactor": 0}}],
                  "extensionsUsed": ["KHR_materials_emissive_strength"]}

    def view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        v = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.bin += data
        self.g["bufferViews"].append(v)
        return len(self.g["bufferViews"]) - 1

    def accessor(self, arr, ctype, typ, count, minmax=None, target=None):
        a = {"bufferView": self.view(arr.tobytes(), target), "componentType": ctype, "count": count, "type": typ}
        if minmax:
            a["min"], a["max"] = minmax
        self.g["accessors"].append(a)
        return len(self.g["accessors"]) - 1

    def mesh(self, pos, nrm, idx, material):
        n = len(pos) // 3
        lo = [min(pos[k::3]) for k in range(3)]
        hi = [max(pos[k::3]) for k in range(3)]
        p = self.accessor(array.array("f", pos), 5126, "VEC3", n, (lo, hi), 34962)
        q = self.accessor(array.array("f", nrm), 5126, "VEC3", n, None, 34962)
        i = self.accessor(array.array("I", idx), 5125, "SCALAR", len(idx), None, 34963)
        self.g["meshes"].append({"primitives": [{"attributes": {"POSITION": p, "NORMAL": q}, "indices": i,
                                                 "material": material}]})
        return len(self.g["meshes"]) - 1

    def node(self, **kw):
        self.g["nodes"].append(kw)
        self.g["scenes"][0]["nodes"].append(len(self.g["nodes"]) - 1)
        return len(self.g["nodes"]) - 1

    def room(self):
        """Floor, ceiling, four walls, a ceiling lamp and a camera."""
        X, Y, Z = ROOM
        quads = [((0, 0, 0), (0, 0, Z), (X, 0, Z), (X, 0, 0)),  # floor, facing up
                 ((0, Y, 0), (X, Y, 0), (X, Y, Z), (0, Y, Z)),  # ceiling, facing down
                 ((0, 0, 0), (X, 0, 0), (X, Y, 0), (0, Y, 0)),  # walls facing in
                 ((0, 0, Z), (0, Y, Z), (X, Y, Z), (X, 0, Z)),
                 ((0, 0, 0), (0, Y, 0), (0, Y, Z), (0, 0, Z)),
                 ((X, 0, 0), (X, 0, Z), (X, Y, Z), (X, Y, 0))]
        pos, idx = [], []
        for q in quads:
            base = len(pos) // 3
            for v in q:
                pos += v
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
        nrm = []
        for q in quads:
            e1 = [q[1][k] - q[0][k] for k in range(3)]
            e2 = [q[2][k] - q[0][k] for k in range(3)]
            n = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]]
            ln = math.sqrt(sum(c * c for c in n))
            nrm += [c / ln for c in n] * 4
        self.node(name="room", mesh=self.mesh(pos, nrm, idx, 0))
        lamp = [X / 2 - 2, Y - 0.01, Z / 2 - 2, X / 2 + 2, Y - 0.01, Z / 2 - 2, X / 2 + 2, Y - 0.01, Z / 2 + 2,
                X / 2 - 2, Y - 0.01, Z / 2 + 2]
        self.node(name="lamp", mesh=self.mesh(lamp, [0, -1, 0] * 4, [0, 1, 2, 0, 2, 3], 1))
        self.g["cameras"] = [{"type": "perspective", "perspective": {"yfov": 1.0, "aspectRatio": 1.5,
                                                                     "znear": 0.01}}]
        # At (1, 2, 1) looking toward the far corner, slightly down.
        yaw = math.atan2(-(X - 2), -(Z - 2))
        pitch = -0.15
        q_yaw = (0, math.sin(yaw / 2), 0, math.cos(yaw / 2))
        q_pitch = (math.sin(pitch / 2), 0, 0, math.cos(pitch / 2))
        self.node(name="camera", camera=0, translation=[1, 2, 1], rotation=quat_mul(q_yaw, q_pitch))

    def write(self, outdir):
        binname = self.name + ".bin"
        self.g["buffers"] = [{"uri": binname, "byteLength": len(self.bin)}]
        with open(os.path.join(outdir, binname), "wb") as f:
            f.write(self.bin)
        with open(os.path.join(outdir, self.name + ".gltf"), "w") as f:
            json.dump(self.g, f, separators=(",", ":"))


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


def unique(name, ntris, outdir):
    """Spheres of 320 triangles (10 stacks x 18 slices ~ 324) scattered in the room."""
    w = Writer(name)
    w.room()
    rng = random.Random(42)
    tp, tn, ti = uv_sphere(10, 18)
    per = len(ti) // 3
    nspheres = (ntris + per - 1) // per
    nv = len(tp) // 3
    done = 0
    while done < nspheres:
        batch = min(100, nspheres - done)
        pos, nrm, idx = array.array("f"), array.array("f"), array.array("I")
        for s in range(batch):
            r = rng.uniform(0.03, 0.12)
            c = (rng.uniform(0.5, ROOM[0] - 0.5), rng.uniform(r, ROOM[1] - 0.5), rng.uniform(0.5, ROOM[2] - 0.5))
            pos.extend([c[k % 3] + r * tp[k] for k in range(len(tp))])
            nrm.extend(tn)
            base = s * nv
            idx.extend([base + i for i in ti])
        w.node(name="spheres%d" % (done // 100), mesh=w.mesh(pos, nrm, idx, 0))
        done += batch
    w.write(outdir)
    return nspheres * per


def instanced(name, copies, outdir, gpu=False):
    """A bumpy sphere of ~100k triangles (159 stacks x 316 slices) in `copies`
    nodes on a grid, each turned about Y and scaled (some non-uniformly, a
    few mirrored); with gpu=True one node's EXT_mesh_gpu_instancing instead."""
    w = Writer(name)
    w.room()
    tp, tn, ti = uv_sphere(159, 316, bump=0.05)
    mesh = w.mesh(tp, tn, ti, 0)
    rng = random.Random(7)
    side = math.ceil(math.sqrt(copies))
    step = (ROOM[0] - 1.0) / side
    trs = []
    for k in range(copies):
        i, j = divmod(k, side)
        s = 0.35 * step * rng.uniform(0.7, 1.0)
        sc = [s, s * rng.uniform(0.6, 1.4), s]
        if k % 10 == 9:
            sc[0] = -sc[0]  # a mirrored copy
        a = rng.uniform(0, 2 * math.pi)
        t = [0.5 + (j + 0.5) * step, abs(sc[1]) * 1.05, 0.5 + (i + 0.5) * step]
        trs.append((t, [0, math.sin(a / 2), 0, math.cos(a / 2)], sc))
    if gpu:
        attrs = {}
        for key, k, typ in (("TRANSLATION", 0, "VEC3"), ("ROTATION", 1, "VEC4"), ("SCALE", 2, "VEC3")):
            flat = array.array("f", [c for x in trs for c in x[k]])
            attrs[key] = w.accessor(flat, 5126, typ, copies)
        w.node(name="copies", mesh=mesh, extensions={"EXT_mesh_gpu_instancing": {"attributes": attrs}})
        w.g["extensionsUsed"].append("EXT_mesh_gpu_instancing")
    else:
        for k, (t, r, sc) in enumerate(trs):
            w.node(name="copy%d" % k, mesh=mesh, translation=t, rotation=r, scale=sc)
    w.write(outdir)
    return copies * (len(ti) // 3)


def rule(name, stacks, slices, copies, outdir):
    """The flattening rule's scenes (bench.c, AJAR_BENCH_RULE): a bumpy
    sphere of slices x (2 stacks - 2) triangles in `copies` nodes on a grid
    over the room's floor, turned and scaled."""
    w = Writer(name)
    w.room()
    tp, tn, ti = uv_sphere(stacks, slices, bump=0.05)
    mesh = w.mesh(tp, tn, ti, 0)
    rng = random.Random(3)
    side = math.ceil(math.sqrt(copies))
    step = (ROOM[0] - 1.0) / side
    for k in range(copies):
        i, j = divmod(k, side)
        s = 0.4 * step * rng.uniform(0.7, 1.0)
        a = rng.uniform(0, 2 * math.pi)
        w.node(name="copy%d" % k, mesh=mesh, translation=[0.5 + (j + 0.5) * step, s, 0.5 + (i + 0.5) * step],
               rotation=[0, math.sin(a / 2), 0, math.cos(a / 2)], scale=[s, s, s])
    w.write(outdir)
    return copies * (len(ti) // 3)


RULE_MESHES = {64: (4, 11), 1024: (16, 34), 16384: (64, 130)}
RULE_COPIES = (4, 16, 64, 256)

SCENES = {
    "unique-1m": lambda d: unique("unique-1m", 1000000, d),
    "unique-10m": lambda d: unique("unique-10m", 10000000, d),
    "inst-100": lambda d: instanced("inst-100", 100, d),
    "inst-1000": lambda d: instanced("inst-1000", 1000, d),
    "inst-1000-gpu": lambda d: instanced("inst-1000-gpu", 1000, d, gpu=True),
}
for _t, (_st, _sl) in RULE_MESHES.items():
    for _u in RULE_COPIES:
        SCENES["rule-%d-%d" % (_t, _u)] = (lambda st, sl, u, t: lambda d: rule("rule-%d-%d" % (t, u), st, sl, u, d))(
            _st, _sl, _u, _t)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    outdir = sys.argv[1]
    os.makedirs(outdir, exist_ok=True)
    for name in sys.argv[2:] or SCENES:
        if name not in SCENES:
            sys.exit("make_scale_scenes.py: unknown scene %s (%s)" % (name, ", ".join(SCENES)))
        out = os.path.join(outdir, name + ".gltf")
        if os.path.exists(out) and os.path.getmtime(out) > os.path.getmtime(__file__):
            continue  # written by this version of the script
        n = SCENES[name](outdir)
        print("wrote %s/%s.gltf (%d triangles)" % (outdir, name, n))


if __name__ == "__main__":
    main()
