#!/bin/sh
# Optional: denoise an Ajar render with Open Image Denoise, before and after.
# Installs pyoidn (bundles OIDN) and OpenEXR from PyPI into build/oidn/venv;
# never part of `make test`. Knobs: SCENE, SPP, SIZE, OUT (default out/oidn).
set -e
SCENE=${SCENE:-scenes/living-room/living-room.gltf}
SPP=${SPP:-16}
SIZE=${SIZE:-512x288}
OUT=${OUT:-out/oidn}
VENV=build/oidn/venv
if [ ! -x "$VENV/bin/python3" ]; then
	python3 -m venv "$VENV"
	"$VENV/bin/pip" install -q pyoidn OpenEXR numpy
fi
mkdir -p "$OUT"
build/ajar render "$SCENE" -o "$OUT/noisy.exr" --png "$OUT/noisy.png" --spp "$SPP" --size "$SIZE" \
	--aov albedo,normal -q
"$VENV/bin/python3" tests/oidn/denoise.py "$OUT/noisy.exr" "$OUT/denoised.exr" "$OUT/denoised.png"
