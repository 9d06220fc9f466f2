#!/bin/sh
# tests/fuzz/run.sh SECONDS TARGET... — runs each libFuzzer harness
# build/fuzz/fuzzers/fuzz_TARGET for SECONDS on its corpus (the seeds in
# tests/fuzz/corpus/TARGET, and what earlier runs kept in
# build/fuzz/corpus/TARGET), one after the other. A crash, sanitizer
# report, leak, input slower than 10 s or allocation past the limits is a
# finding: its input is kept in build/fuzz/findings/ and the script exits
# 1. Prints each harness's executions, executions per second and coverage.
# FUZZ_BIN_DIR runs harnesses from elsewhere (a long campaign's copies, so
# a rebuild meanwhile does not change what runs).
set -u
seconds=$1
shift
status=0
mkdir -p build/fuzz/findings
for t in "$@"; do
	bin=${FUZZ_BIN_DIR:-build/fuzz/fuzzers}/fuzz_$t
	mkdir -p build/fuzz/corpus/$t
	log=build/fuzz/fuzz_$t.log
	# 4200 MB: above the largest allocation the limits allow (an EXR of
	# 2^28 pixels as float RGBA, 4 GiB); -rss_limit_mb bounds what is used.
	ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 \
	UBSAN_OPTIONS=print_stacktrace=1 \
		"$bin" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2560 -malloc_limit_mb=4200 \
		-max_len=65536 -print_final_stats=1 -artifact_prefix=build/fuzz/findings/$t- \
		build/fuzz/corpus/$t tests/fuzz/corpus/$t >"$log" 2>&1
	rc=$?
	runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log")
	rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log")
	cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1)
	ft=$(grep -o 'ft: [0-9]*' "$log" | tail -1)
	corpus=$(ls build/fuzz/corpus/$t | wc -l)
	if [ $rc -eq 0 ]; then
		echo "fuzz_$t: ${runs:-?} runs in ${seconds} s, ${rate:-?}/s, ${cov:-cov: ?} edges, ${ft:-ft: ?} features, $corpus inputs kept: no finding"
	else
		echo "fuzz_$t: FINDING (exit $rc) after ${runs:-?} runs; see $log and build/fuzz/findings/"
		grep -E "ERROR|SUMMARY|==[0-9]+==|runtime error" "$log" | head -5
		status=1
	fi
done
exit $status
