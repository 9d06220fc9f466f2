#!/bin/sh
# tests/gpu/pocl_cost.sh AJAR [OUT.tsv] — PoCL's cost per integrator and
# scene on one thread, for before/after comparisons of kernel changes
# (kernels/README.md, "On GPUs: subpaths in global memory"): the
# instructions of the render_pass kernel (callgrind, 64x64 at 4 spp) and
# the user CPU time of a render (128x128 at 16 spp). Extra render options
# come from $AJAR_COST_ARGS; the environment (AJAR_SUBPATHS, ...) passes on.
set -eu
AJAR=$1
OUT=${2:-/dev/stdout}
SCENES=${AJAR_COST_SCENES:-"cornell window-room door-ajar living-room"}
INTS=${AJAR_COST_INTEGRATORS:-"pt bdpt portal"}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
export POCL_MAX_PTHREAD_COUNT=1
printf 'scene\tintegrator\tkernel_Ir\tuser_s\n' >"$OUT"
for sc in $SCENES; do
	for it in $INTS; do
		g=scenes/$sc/$sc.gltf
		# warm the kernel cache outside valgrind
		"$AJAR" render "$g" -o "$TMP/w.exr" --size 8x8 --spp 1 --integrator "$it" -q ${AJAR_COST_ARGS:-}
		valgrind --tool=callgrind --callgrind-out-file="$TMP/cg.out" "$AJAR" render "$g" -o "$TMP/c.exr" \
			--size 64x64 --spp 4 --integrator "$it" -q ${AJAR_COST_ARGS:-} 2>/dev/null
		ir=$(callgrind_annotate --threshold=100 "$TMP/cg.out" 2>/dev/null |
			awk '/render_pass|parallel\.so|\.so:_pocl|pocl_kernel/ && /^ *[0-9,]+/ {gsub(",","",$1); s+=$1} END {print s+0}')
		t=$( { /usr/bin/time -f %U "$AJAR" render "$g" -o "$TMP/t.exr" --size 128x128 --spp 16 \
			--integrator "$it" -q ${AJAR_COST_ARGS:-} ; } 2>&1 | tail -1)
		printf '%s\t%s\t%s\t%s\n' "$sc" "$it" "$ir" "$t" >>"$OUT"
	done
done
