#!/bin/sh
# tests/gpu/pocl_cost.sh OUT.tsv AJAR [AJAR ...] — PoCL's cost per scene
# and integrator on one thread, for before/after comparisons of kernel
# changes (kernels/integrator/README.md, "Where subpaths live"): the
# instructions of the render_pass kernel's code (callgrind, $AJAR_COST_CG,
# default "32x32 2": size and spp) and the user CPU time of a render
# ($AJAR_COST_TIME, default "64x64 8"). The binaries take turns at each
# scene and integrator, so a change in the machine's load hits them alike.
# $AJAR_COST_SCENES and $AJAR_COST_INTEGRATORS narrow the set; the
# environment (AJAR_SUBPATHS, ...) passes on to every render.
set -eu
OUT=$1
shift
SCENES=${AJAR_COST_SCENES:-"cornell window-room door-ajar living-room"}
INTS=${AJAR_COST_INTEGRATORS:-"pt bdpt portal"}
set -- "$@"
CG=${AJAR_COST_CG:-"32x32 2"}
TM=${AJAR_COST_TIME:-"64x64 8"}
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
export POCL_MAX_PTHREAD_COUNT=1
printf 'scene\tintegrator\tbinary\tkernel_Ir\tuser_s\n' >"$OUT"
for sc in $SCENES; do
	for it in $INTS; do
		g=scenes/$sc/$sc.gltf
		for AJAR in "$@"; do
			# Warm the kernel caches and PoCL's work-group variants first:
			# under valgrind PoCL sees another CPU (valgrind's CPUID, a
			# Haswell), so its build is made under valgrind's plain tool,
			# several times faster than under callgrind.
			valgrind --tool=none "$AJAR" render "$g" -o "$TMP/w.exr" --size ${CG% *} --spp 1 \
				--integrator "$it" -q 2>/dev/null
			"$AJAR" render "$g" -o "$TMP/w.exr" --size ${TM% *} --spp 1 --integrator "$it" -q
			valgrind --tool=callgrind --callgrind-out-file="$TMP/cg.out" "$AJAR" render "$g" -o "$TMP/c.exr" \
				--size ${CG% *} --spp ${CG#* } --integrator "$it" -q 2>/dev/null
			ir=$(callgrind_annotate --threshold=100 "$TMP/cg.out" 2>/dev/null |
				awk '/render_pass\.so/ && /^ *[0-9,]+/ {gsub(",","",$1); s+=$1} END {print s+0}')
			t=$( { /usr/bin/time -f %U "$AJAR" render "$g" -o "$TMP/t.exr" --size ${TM% *} --spp ${TM#* } \
				--integrator "$it" -q; } 2>&1 | tail -1)
			printf '%s\t%s\t%s\t%s\t%s\n' "$sc" "$it" "$AJAR" "$ir" "$t" >>"$OUT"
		done
	done
done
