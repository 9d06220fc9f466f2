#!/bin/bash
# tests/gpu/run.sh — the GPU check of issue 23, one prepared command for a
# machine with an NVIDIA GPU (H100/H200, OpenCL through NVIDIA's ICD).
# First, here: sh tests/gpu/pack.sh (fills build/gpu-carry). Then, with the
# device tool: command "bash tests/gpu/run.sh", carry ["build/gpu-carry"],
# timeout_s 590. It needs no compiler there, and stays within ~9 minutes
# (each step has a time limit; what is left out is said).
#   1. the GPU is listed (ajar devices); each program's build time and
#      private memory a work-item, for both subpath layouts (kernel_info);
#   2. images: pt, bdpt and portal on living-room and door-ajar, 128x128 at
#      16 spp, seed 7, on the GPU, against PoCL's (ref/, made by pack.sh):
#      the means within 3e-5 relative (src/device/README.md, "Build options"), for
#      both subpath layouts (AJAR_SUBPATHS=private / global);
#   3. speed: Msamples/s of each integrator and layout on living-room
#      640x360 and door-ajar 512x512 (kernels/README.md's GPU table), against
#      PoCL's two cores (ref/speed.tsv, and the README table's figures),
#      with the issue's targets: bdpt >= 40x, portal >= 30x;
#   4. the device tests (test_layout, test_traversal, test_subpaths,
#      test_render, test_integrators) on the GPU, as far as time allows.
# Results: summary.txt, renders.log, tests.log under $OUT (else /tmp/gpu-out).
set -u
C=build/gpu-carry
O=${OUT:-/tmp/gpu-out}
mkdir -p "$O"
S=$O/summary.txt
: >"$S"
say() { echo "$*" | tee -a "$S"; }
if [ ! -x "$C/bin/ajar" ]; then
	say "no $C/bin/ajar: run tests/gpu/pack.sh on the build machine and carry build/gpu-carry"
	exit 2
fi
T0=$SECONDS
left() { echo $((${GPU_CHECK_SECONDS:-540} - (SECONDS - T0))); }
export LD_LIBRARY_PATH=$PWD/$C/lib:/usr/local/nvidia/lib64:/usr/local/nvidia/lib:/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}
# Debian's ICD loader (carried) reads OCL_ICD_VENDORS: the machine's ICDs
# and NVIDIA's by name, where /etc/OpenCL/vendors lacks it.
if [ ! -e /etc/OpenCL/vendors/nvidia.icd ]; then
	mkdir -p /tmp/gpu-icd
	cp /etc/OpenCL/vendors/*.icd /tmp/gpu-icd/ 2>/dev/null
	lib=$(ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}')
	[ -n "$lib" ] || lib=$(find /usr/local/nvidia /usr/lib /usr/lib64 /usr/local/cuda* -name 'libnvidia-opencl.so*' \
		2>/dev/null | head -1)
	say "NVIDIA's OpenCL library: ${lib:-not found (trying the name)}"
	echo "${lib:-libnvidia-opencl.so.1}" >/tmp/gpu-icd/nvidia.icd
	export OCL_ICD_VENDORS=/tmp/gpu-icd
fi
export AJAR_CACHE_DIR=/tmp/gpu-ajar-cache
AJAR=$C/bin/ajar
R=$O/renders.log
: >"$R"
nvidia-smi -L 2>&1 | tee -a "$S"
"$AJAR" devices 2>&1 | tee -a "$S"
DEV=${GPU_DEVICE:-gpu}
if ! "$AJAR" render scenes/cornell/cornell.gltf -o /tmp/gpu-probe.exr --size 16x16 --spp 1 --device "$DEV" -q; then
	say "no OpenCL GPU device '$DEV' (see above); stopping"
	exit 3
fi

say ""
say "== programs: build time (cold), private memory a work-item, plan for 640x360 (kernel_info)"
timeout 300 "$C/bin/kernel_info" "$DEV" 230400 2>&1 | tee -a "$S"

# render LAYOUT SECONDS-LIMIT ARGS...: one render on the GPU, its stderr to renders.log
render() {
	local layout=$1 lim=$2
	shift 2
	echo "== AJAR_SUBPATHS=$layout ajar render $*" >>"$R"
	AJAR_SUBPATHS=$layout timeout "$lim" "$AJAR" render "$@" --device "$DEV" >>"$R" 2>&1
}

say ""
say "== images against PoCL (128x128, 16 spp, seed 7; means within 3e-5 relative)"
for sc in living-room door-ajar; do
	for it in pt bdpt portal; do
		for layout in private global; do
			[ "$it" = pt ] && [ "$layout" = global ] && continue
			if [ "$(left)" -lt 200 ]; then
				say "$sc $it $layout: left out (time)"
				continue
			fi
			t=$SECONDS
			if render $layout 240 "scenes/$sc/$sc.gltf" -o "/tmp/gpu-$sc-$it-$layout.exr" --size 128x128 \
				--spp 16 --seed 7 --integrator "$it"; then
				say "$sc $it $layout ($((SECONDS - t)) s, build included): $("$C/bin/exr_compare" \
					"$C/ref/$sc-$it.exr" "/tmp/gpu-$sc-$it-$layout.exr")"
			else
				say "$sc $it $layout: render failed or timed out (renders.log)"
			fi
		done
	done
done

say ""
say "== speed (Msamples/s of a ${GPU_SPEED_SECONDS:-6}-s render after a 1-spp warm-up; PoCL: two cores)"
say "scene	integrator	layout	gpu	pocl_now	ratio	pocl_readme	ratio	target"
readme() { # the PoCL column of kernels/README.md's GPU table (two cores, earlier kernels)
	case "$1 $2" in
	"living-room pt") echo 0.54 ;; "living-room bdpt") echo 0.41 ;; "living-room portal") echo 0.42 ;;
	"door-ajar bdpt") echo 0.37 ;; "door-ajar portal") echo 0.10 ;; *) echo - ;;
	esac
}
for job in "living-room 640x360" "door-ajar 512x512"; do
	set -- $job
	sc=$1 size=$2
	for it in pt bdpt portal; do
		for layout in private global; do
			[ "$it" = pt ] && [ "$layout" = global ] && continue
			if [ "$(left)" -lt 90 ]; then
				say "$sc	$it	$layout	left out (time)"
				continue
			fi
			# a warm-up render at the same size first (PoCL builds a variant per size)
			if ! render $layout 60 "scenes/$sc/$sc.gltf" -o /tmp/gpu-speed.exr --size "$size" --spp 1 \
				--integrator "$it" ||
				! render $layout 60 "scenes/$sc/$sc.gltf" -o /tmp/gpu-speed.exr --size "$size" \
					--time "${GPU_SPEED_SECONDS:-6}" --spp 100000 --integrator "$it"; then
				say "$sc	$it	$layout	failed (renders.log)"
				continue
			fi
			g=$(grep 'done:' "$R" | tail -1 | sed -n 's/.*(\([0-9.e+-]*\) Msamples\/s).*/\1/p')
			p=$(awk -v s="$sc" -v i="$it" '$1 == s && $2 == i {print $4}' "$C/ref/speed.tsv")
			q=$(readme "$sc" "$it")
			tgt=-
			[ "$it" = bdpt ] && tgt=">=40x"
			[ "$it" = portal ] && tgt=">=30x"
			awk -v sc="$sc" -v it="$it" -v l="$layout" -v g="$g" -v p="${p:--}" -v q="$q" -v t="$tgt" \
				'function r(a, b) { return (b + 0 > 0 && a + 0 > 0) ? sprintf("%.1fx", a / b) : "-" }
				 BEGIN {printf "%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n", sc, it, l, g, p, r(g, p), q, r(g, q), t}' |
				tee -a "$S"
		done
	done
done

say ""
say "== device tests on the GPU (tests.log)"
: >"$O/tests.log"
for t in test_layout test_traversal test_subpaths test_render test_integrators; do
	l=$(left)
	if [ "$l" -lt 30 ]; then
		say "$t: left out (time)"
		continue
	fi
	timeout "$l" "$C/bin/$t" >>"$O/tests.log" 2>&1
	rc=$?
	say "$t: $([ $rc = 0 ] && echo passed || ([ $rc = 124 ] && echo "timed out" || echo "FAILED (rc $rc)"))"
done
say ""
say "total $((SECONDS - T0)) s"
