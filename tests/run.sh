#!/bin/sh
# Runs the given test binaries from build dir $1; prints each result and a
# closing summary line; exits non-zero if any failed.
dir=$1; shift
pass=0; fail=0; failed=""
for t in "$@"; do
	echo "=== $t"
	if "$dir/tests/$t"; then pass=$((pass + 1)); else fail=$((fail + 1)); failed="$failed $t"; fi
done
echo
[ -n "$failed" ] && echo "failed:$failed"
echo "$pass passed, $fail failed"
[ "$fail" = 0 ]
