"""sky_eff.py — variance per sample and CPU time per sample of Ajar's
integrators, for choosing strategies on the sky scenes (kernels/README.md, "How the figures were measured"). Not part of make test or
bench-peers; run with the peers' venv:

  build/peers/venv/bin/python tests/peers/sky_eff.py AJAR SCENE INTEGRATOR SPP [VAR=VALUE ...]

renders seeds 1 and 2 (or seeds=A,B) at 64 x 64 with one PoCL thread (depth=N: at
--max-depth N, as bench-peers renders at 32; default the scene's; mis=NAME: with
--mis NAME), and prints spp, the
relative variance of one render (mean over pixels and channels of
(a - b)^2 / 2 / (r^2 + (0.1 mean r)^2), r the two seeds' mean, the error
measure of tests/bench/bench.c without a reference), relvar x spp (the variance
per sample), the CPU seconds per sample (user + system of the render minus
that of a 1-spp render: set-up left out) and their product, the
inefficiency (lower is better; relMSE at equal CPU time is proportional to
it). VAR=VALUE pairs go into the renderer's environment (the device knobs of
src/device/README.md, e.g. AJAR_CL_OPTIONS). To measure another strategy
choice, change it in src/prepare/policy.c, rebuild, and run this again.
"""
import os
import resource
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import images  # noqa: E402


def render(ajar, scene, integ, spp, seed, env, out, depth=None, mis=None):
	cmd = [ajar, "render", scene, "--integrator", integ, "--size", "64x64", "--spp", str(spp), "--seed", str(seed),
	       "-o", out, "-q"] + (["--max-depth", str(depth)] if depth else []) + (["--mis", mis] if mis else [])
	before = resource.getrusage(resource.RUSAGE_CHILDREN)
	r = subprocess.run(cmd, env=env, capture_output=True, text=True)
	after = resource.getrusage(resource.RUSAGE_CHILDREN)
	if r.returncode != 0:
		raise SystemExit(f"sky_eff: {' '.join(cmd)} failed: {r.stderr.strip()}")
	cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
	return images.read_exr(out)[0], cpu


def main():
	if len(sys.argv) < 5:
		raise SystemExit(__doc__)
	ajar, scene, integ, spp = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
	env = dict(os.environ, POCL_MAX_PTHREAD_COUNT="1")
	seeds = (1, 2)
	depth = None
	mis = None
	for kv in sys.argv[5:]:
		k, v = kv.split("=", 1)
		if k == "seeds":  # seeds=3,4: another pair
			seeds = tuple(int(x) for x in v.split(","))
		elif k == "depth":  # depth=32: the bench's --max-depth (default: the scene's)
			depth = int(v)
		elif k == "mis":  # mis=balance: --mis (default: the renderer's, auto)
			mis = v
		else:
			env[k] = v
	tmp = os.environ.get("TMPDIR", "/tmp")
	tag = f"{os.getpid()}"
	render(ajar, scene, integ, 1, 3, env, f"{tmp}/sky_eff_{tag}_0.exr", depth, mis)  # builds the kernel if not cached
	_, c1 = render(ajar, scene, integ, 1, 3, env, f"{tmp}/sky_eff_{tag}_0.exr", depth, mis)
	a, ca = render(ajar, scene, integ, spp, seeds[0], env, f"{tmp}/sky_eff_{tag}_1.exr", depth, mis)
	b, cb = render(ajar, scene, integ, spp, seeds[1], env, f"{tmp}/sky_eff_{tag}_2.exr", depth, mis)
	r = 0.5 * (a + b)
	m = float(r.mean())
	relvar = float(np.mean((a - b) ** 2 / 2.0 / (r * r + 0.01 * m * m)))
	per = max(1e-9, (0.5 * (ca + cb) - c1) / (spp - 1))
	label = " ".join(sys.argv[5:])
	print(f"{os.path.basename(scene):24s} {integ:7s} {spp:5d} spp  mean {m:.5f}  relvar {relvar:.3e}  "
	      f"var/spp {relvar * spp:.4f}  cpu/spp {per * 1e3:.1f} ms  ineff {relvar * spp * per:.5f}  {label}",
	      flush=True)
	for k in range(3):
		os.remove(f"{tmp}/sky_eff_{tag}_{k}.exr")


if __name__ == "__main__":
	main()
