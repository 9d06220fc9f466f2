"""backend.py — runs one peer renderer on one scene, in its own process.

  python backend.py RENDERER SCENE.gltf OUT.npy --size WxH --depth D
                    (--seconds T | --spp N) [--seed S] [--threads N] [--integrator NAME]

RENDERER is mitsuba, cycles or luxcore (backend_<name>.py). The scene is
read by scene.py, must be exactly Lambertian (the driver passes the matched
variant where the shipped scene is not), and is rebuilt in the renderer from
the same world-space triangles. The image goes to OUT.npy as (H, W, 3)
float32 linear RGB, row 0 at the top; the last line printed is a JSON object
with spp (samples per pixel reached), render_seconds (from the start of
rendering to the image being in memory) and setup_seconds (import and
scene build). Each renderer runs in its own process so a crash cannot take
the driver down, and so bpy's and the others' libraries never meet.
"""
import argparse
import importlib
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from scene import Scene  # noqa: E402


def main():
	t0 = time.perf_counter()
	p = argparse.ArgumentParser()
	p.add_argument("renderer")
	p.add_argument("scene")
	p.add_argument("out")
	p.add_argument("--size", required=True)
	p.add_argument("--depth", type=int, required=True)
	p.add_argument("--seconds", type=float, default=0.0)
	p.add_argument("--spp", type=int, default=0)
	p.add_argument("--seed", type=int, default=1)
	p.add_argument("--threads", type=int, default=os.cpu_count())
	p.add_argument("--integrator", default="")
	a = p.parse_args()
	if (a.seconds > 0) == (a.spp > 0):
		p.error("give exactly one of --seconds and --spp")
	a.width, a.height = (int(x) for x in a.size.split("x"))
	s = Scene(a.scene)
	if a.integrator != "principled":  # cycles-principled: glTF's materials (energy.py)
		s.check_lambertian()
	mod = importlib.import_module("backend_" + a.renderer)
	rgb, info = mod.render(s, a, t0)
	import numpy as np
	np.save(a.out, np.ascontiguousarray(rgb, dtype=np.float32))
	info["setup_seconds"] = round(info.get("setup_seconds", 0.0), 3)
	sys.stdout.write(json.dumps(info) + "\n")
	sys.stdout.flush()
	# pyluxcore may hang in its log handler at interpreter exit.
	os._exit(0)


if __name__ == "__main__":
	main()
