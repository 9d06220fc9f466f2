#!/bin/sh
# Runs the given test binaries from build dir $1; prints each result and a
# closing summary line; exits non-zero if any failed.
dir=$1; shift
pass=0; fail=0; failed=""; times=""
for t in "$@"; do
	echo "=== $t"
	t0=$(date +%s)
	if "$dir/tests/$t"; then pass=$((pass + 1)); else fail=$((fail + 1)); failed="$failed $t"; fi
	times="$times $t $(($(date +%s) - t0))s"
done
echo
# Seconds per binary, to keep the suite inside CI's budget (tests/README.md).
echo "times:$times"
[ -n "$failed" ] && echo "failed:$failed"
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
