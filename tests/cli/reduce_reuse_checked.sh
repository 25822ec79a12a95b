#!/usr/bin/env bash
# reduce_reuse_checked.sh IMPACTLAB WORKDIR: issue 14, item 4, as a user meets
# it. On a generated quick session (two photo runs, a CSV run, a typed-in run):
# - a second reduce reuses the three measured runs (typed-in runs never reuse);
# - after a NaN is written into one run's xmax in the results file (its bytes
#   patched where h5dump says the data lie), reduce notes "not reusing run X
#   from FILE: xmax[2] is nan" and measures that run again;
# - with --convention thesis nothing is reused and the file says thesis.
# Needs h5dump (hdf5-tools); skipped (77) without it.
set -u
exe=$1 work=$2
command -v h5dump >/dev/null || { echo "h5dump not installed: skipped"; exit 77; }
dir=$work/reuse-checked
rm -rf "$dir" && mkdir -p "$dir" || exit 1
"$exe" synth --out "$dir/s" --preset quick --csv-run --typed-run >/dev/null 2>&1 || { echo "synth failed"; exit 1; }
out=$dir/out.h5
fail() { echo "$1"; printf '%s\n' "$output"; exit 1; }

output=$("$exe" reduce "$dir/s" -o "$out" 2>&1) || fail "the first reduce failed"
output=$("$exe" reduce "$dir/s" -o "$out" 2>&1) || fail "the second reduce failed"
printf '%s\n' "$output" | grep -Eq '4 run\(s\): 4 ok \(3 reused\)' || fail "unchanged runs were not reused"

run=$(h5dump -n "$out" | awk '$1 == "group" && $2 ~ /^\/runs\/[^\/]+$/ { sub("/runs/", "", $2); print $2; exit }')
[ -n "$run" ] || fail "no run in $out"
offset=$(h5dump -p -H -d "/runs/$run/rebounds/xmax" "$out" | awk '$1 == "OFFSET" { print $2; exit }')
[ -n "$offset" ] || fail "no contiguous xmax for run $run"
# xmax[2] = NaN (IEEE 754 quiet NaN, little-endian).
printf '\000\000\000\000\000\000\370\177' | dd of="$out" bs=1 seek=$((offset + 16)) conv=notrunc status=none
output=$("$exe" reduce "$dir/s" -o "$out" 2>&1) || fail "the reduce after the NaN failed"
printf '%s\n' "$output"
printf '%s\n' "$output" | grep -Eq "note: not reusing run $run from .*out\.h5: xmax\[2\] is nan" ||
  fail "no note for the NaN"
printf '%s\n' "$output" | grep -Eq '4 run\(s\): 4 ok \(2 reused\)' || fail "the others were not reused"

output=$("$exe" reduce "$dir/s" -o "$out" --convention thesis 2>&1) || fail "the thesis reduce failed"
printf '%s\n' "$output" | grep -Eq '4 run\(s\): 4 ok \(0 reused\)' || fail "runs reused across conventions"
h5dump -a /convention "$out" | grep -q '"thesis"' || fail "the file does not say thesis"
echo "reuse checked"
