#!/usr/bin/env python3
"""embree_build.py -- Embree's BVH build time on glTF scenes, the figure Ajar's
build is compared with (src/prepare/README.md, "The BVH"; issue 42).

usage: build/peers/venv/bin/python tests/peers/embree_build.py SCENE.gltf [...]

Needs numpy and embreex (`build/peers/venv/bin/pip install embreex`). Every
mesh node's triangles go into one Embree scene in world space (node matrices
and TRS applied; float positions, any unsigned index type, TRIANGLES mode:
what the shipped and scale scenes use); portals are left out, as Ajar leaves
them out of its BVH. The build runs at the first ray query
(rtcCommitScene); it is timed three times (a new scene each), printing wall
and process CPU seconds. Embree uses every core TBB sees: restrict it with
`taskset -c 0` for one core.
"""
import json
import os
import sys
import time

import numpy as np
from embreex import mesh_construction as mc
from embreex import rtcore_scene as rs

DTYPES = {5121: np.uint8, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def quat_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def local_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    m = np.eye(4)
    m[:3, :3] = quat_matrix(node.get("rotation", [0, 0, 0, 1])) * np.array(node.get("scale", [1, 1, 1]))
    m[:3, 3] = node.get("translation", [0, 0, 0])
    return m


def load(path):
    """World-space vertices (n, 3) and triangle indices (m, 3) of every mesh node."""
    g = json.load(open(path))
    folder = os.path.dirname(path)
    buffers = [np.fromfile(os.path.join(folder, b["uri"]), dtype=np.uint8) for b in g["buffers"]]

    def accessor(i):
        a = g["accessors"][i]
        v = g["bufferViews"][a["bufferView"]]
        dt = np.dtype(DTYPES[a["componentType"]])
        k = COMPONENTS[a["type"]]
        start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
        stride = v.get("byteStride", 0)
        raw = buffers[v["buffer"]]
        if stride and stride != dt.itemsize * k:
            rows = np.lib.stride_tricks.as_strided(raw[start:], (a["count"], dt.itemsize * k), (stride, 1))
            return np.ascontiguousarray(rows).view(dt).reshape(a["count"], k)
        return np.frombuffer(raw[start:start + a["count"] * k * dt.itemsize].tobytes(), dt).reshape(a["count"], k)

    verts, tris, base = [], [], 0
    roots = g["scenes"][g.get("scene", 0)]["nodes"] if "scenes" in g else range(len(g["nodes"]))
    stack = [(r, np.eye(4)) for r in roots]
    while stack:
        ni, parent = stack.pop()
        node = g["nodes"][ni]
        world = parent @ local_matrix(node)
        if "mesh" in node and not node.get("extras", {}).get("portal"):
            for pr in g["meshes"][node["mesh"]]["primitives"]:
                if pr.get("mode", 4) != 4:
                    continue
                p = accessor(pr["attributes"]["POSITION"]).astype(np.float64)
                p = (p @ world[:3, :3].T + world[:3, 3]).astype(np.float32)
                idx = accessor(pr["indices"]).reshape(-1, 3).astype(np.int64) if "indices" in pr else \
                    np.arange(len(p)).reshape(-1, 3)
                verts.append(p)
                tris.append(idx + base)
                base += len(p)
        stack += [(c, world) for c in node.get("children", [])]
    return np.concatenate(verts), np.concatenate(tris).astype(np.int32)


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for path in sys.argv[1:]:
        v, t = load(path)
        o = np.zeros((1, 3), np.float32)
        d = np.ones((1, 3), np.float32)
        times = []
        for _ in range(3):
            s = rs.EmbreeScene()
            mc.TriangleMesh(s, v, t)
            w0, c0 = time.perf_counter(), time.process_time()
            s.run(o, d)  # commits: the build
            times.append((time.perf_counter() - w0, time.process_time() - c0))
        print("%s: %d triangles, Embree build %s s wall (cpu %s s)" % (
            path, len(t), " ".join("%.3f" % w for w, _ in times), " ".join("%.3f" % c for _, c in times)))


if __name__ == "__main__":
    main()
