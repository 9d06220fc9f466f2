#!/usr/bin/env python3
"""kernel_profile.py -- where a render's kernel time goes on PoCL's CPU device (issue 45).

  kernel_profile.py AJAR SCENE.gltf INTEGRATOR [SIZE SPP [FREQ [RENDER-OPTION ...]]]

Renders SCENE with the render program built with -g (AJAR_CL_OPTIONS; debug information
changes no code: the image is the same bits), once to warm the caches and once under
`perf record` on one PoCL thread, then maps every sample in PoCL's render_pass.so to the
innermost inlined source frame outside the helpers (kernels/base/, sample/sampling.h's
warps, sample/roulette.h; llvm-symbolizer walks the inlined frames), and that frame's file
to a part of the work:

  traversal          geom/bvh.h, geom/visibility.h (closest hits and shadow rays)
  shading, textures  material/*, geom/surface.h (what a hit knows, the BSDF)
  lights, sky        light/* (emitters, punctual lights, the sky through the portals)
  MIS                mis/*
  film               film/*
  random numbers     sample/rng.h, sample/qmc.h (PCG, the low-discrepancy pairs)
  camera             geom/camera.h
  integrator         integrator/*, geom/portal_crossing.h, the entry point (ajar.cl)
  other              frames only in helpers or without a line (PoCL's work-group loop)

It prints each part's share of the kernel's samples, and the kernel's share of the
process (the rest: start-up, the host, PoCL's runtime). Shares of CPU time, sampled
(cpu-clock), not instruction counts. Needs perf and llvm-symbolizer; SIZE defaults to
128x128, SPP to 16, FREQ (samples per second) to 2000; options after FREQ go to the
render (e.g. --portals none). AJAR_PROFILE_LINES=N also prints
the N source lines with the most samples.
"""
import collections
import os
import shutil
import subprocess
import sys
import tempfile

PARTS = [
    ("traversal", ("geom/bvh.h", "geom/visibility.h")),
    ("shading, textures", ("material/", "geom/surface.h")),
    ("lights, sky", ("light/",)),
    ("MIS", ("mis/",)),
    ("film", ("film/",)),
    ("random numbers", ("sample/rng.h", "sample/qmc.h")),
    ("camera", ("geom/camera.h",)),
    ("integrator", ("integrator/", "geom/portal_crossing.h", "ajar.cl")),
]


# Helpers count for their caller: vector math, warps (a BSDF's or a light's), roulette.
HELPERS = ("base/", "sample/sampling.h", "sample/roulette.h")


def part_of(frames):
    """frames: the inlined source lines (file:line), innermost first. The part, and the
    line that decided it."""
    for f in frames:
        if any(h in f for h in HELPERS) or f.startswith("??"):
            continue
        for name, keys in PARTS:
            if any(k in f for k in keys):
                return name, f
        return "other", f
    return "other", "?"


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__)
    ajar, scene, integ = sys.argv[1:4]
    size = sys.argv[4] if len(sys.argv) > 4 else "128x128"
    spp = sys.argv[5] if len(sys.argv) > 5 else "16"
    freq = sys.argv[6] if len(sys.argv) > 6 else "2000"
    extra = sys.argv[7:]
    top = int(os.environ.get("AJAR_PROFILE_LINES", "0"))
    env = dict(os.environ, POCL_MAX_PTHREAD_COUNT="1")
    env["AJAR_CL_OPTIONS"] = (env.get("AJAR_CL_OPTIONS", "") + " -g").strip()
    tmp = tempfile.mkdtemp()
    try:
        profile(ajar, scene, integ, size, spp, freq, top, env, tmp, extra)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def profile(ajar, scene, integ, size, spp, freq, top, env, tmp, extra):
    render = [ajar, "render", scene, "-o", os.path.join(tmp, "x.exr"), "--integrator", integ, "-q"] + extra
    subprocess.run(render + ["--size", "16x16", "--spp", "1"], env=env, check=True,
                   stderr=subprocess.DEVNULL)
    data = os.path.join(tmp, "perf.data")
    subprocess.run(["perf", "record", "-q", "-F", freq, "-o", data, "--"] + render +
                   ["--size", size, "--spp", spp], env=env, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    # Samples as symbol + offset: perf prints run-time addresses, the symbolizer wants
    # the file's, and a symbol's address in the file is what nm says.
    out = subprocess.run(["perf", "script", "-i", data, "-F", "ip,sym,symoff,dso"],
                         capture_output=True, text=True, check=True).stdout
    total = 0
    by_dso = collections.defaultdict(collections.Counter)
    for line in out.splitlines():
        parts = line.split()
        if len(parts) < 2:
            continue
        total += 1
        dso = parts[-1].strip("()")
        if os.path.basename(dso) == "render_pass.so" and "+0x" in parts[1]:
            by_dso[dso][parts[1]] += 1
    counts = collections.Counter()
    lines_hit = collections.Counter()
    ksamples = 0
    for dso, ips in by_dso.items():
        nm = subprocess.run(["nm", dso], capture_output=True, text=True, check=True).stdout
        base = {f[2]: int(f[0], 16) for f in (l.split() for l in nm.splitlines()) if len(f) == 3}
        addrs = [a for a in ips if a.split("+0x")[0] in base]
        # LLVM style: per address, pairs of lines (function, file:line:column), the
        # innermost inlined frame first, and an empty line after each address.
        sym = subprocess.run(["llvm-symbolizer", "--obj=" + dso, "--inlining"],
                             input="".join("0x%x\n" % (base[a.split("+0x")[0]] + int(a.split("+0x")[1], 16))
                                           for a in addrs), capture_output=True,
                             text=True, check=True).stdout
        groups = []
        for block in sym.split("\n\n"):
            lines = block.strip("\n").splitlines()
            if lines:
                groups.append([loc.rsplit(":", 1)[0] for loc in lines[1::2]])
        if len(groups) != len(addrs):
            sys.exit("kernel_profile: llvm-symbolizer gave %d answers for %d addresses" %
                     (len(groups), len(addrs)))
        for a, frames in zip(addrs, groups):
            part, where = part_of(frames)
            counts[part] += ips[a]
            lines_hit[where.split("/kernels/")[-1]] += ips[a]
            ksamples += ips[a]
    if not ksamples:
        sys.exit("kernel_profile: no samples in render_pass.so")
    print("%s %s %s %s spp: %d samples, %.1f%% in the kernel" %
          (os.path.basename(scene), integ, size, spp, ksamples, 100.0 * ksamples / total))
    for name, _ in PARTS + [("other", ())]:
        print("  %-18s %5.1f%%" % (name, 100.0 * counts[name] / ksamples))
    if top:
        print("  hottest lines:")
        for where, n in lines_hit.most_common(top):
            print("  %5.1f%%  %s" % (100.0 * n / ksamples, where))


if __name__ == "__main__":
    main()
