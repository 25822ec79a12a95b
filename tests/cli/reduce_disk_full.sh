#!/usr/bin/env bash
# reduce_disk_full.sh IMPACTLAB SESSION WORKDIR: a disk that fills up while
# `impactlab reduce` writes must never damage the earlier results file.
# A file size limit (ulimit -f, with SIGXFSZ ignored so write() fails with
# EFBIG) stands in for the full disk. For each limit below the file's size:
# the exit status is non-zero, the message names the output, the old file is
# byte-identical and no temporary is left. Limits above it must succeed.
set -u
exe=$1 session=$2 work=$3
rm -rf "$work" && mkdir -p "$work" || exit 1
out=$work/results.h5
"$exe" reduce "$session" -o "$out" -q || { echo "setup: the first reduce failed"; exit 1; }
cp "$out" "$work/good.h5"
size_kb=$(( ($(stat -c %s "$out") + 1023) / 1024 ))
failed=0 trials=0 refused=0
for kb in 4 16 64 256 $((size_kb - 1)) $((size_kb + 1)); do
  [ "$kb" -ge 1 ] || continue
  trials=$((trials + 1))
  msg=$( (trap '' XFSZ; ulimit -f "$kb" && exec "$exe" reduce "$session" -o "$out" --fresh -q) 2>&1 )
  code=$?
  leftovers=$(find "$work" -name '*.tmp-*')
  if [ -n "$leftovers" ]; then echo "limit ${kb} KB: temporary left: $leftovers"; failed=$((failed + 1)); fi
  if [ "$kb" -lt "$size_kb" ]; then
    refused=$((refused + 1))
    if [ "$code" -eq 0 ]; then echo "limit ${kb} KB: exit 0 for a file of ${size_kb} KB"; failed=$((failed + 1)); fi
    if ! printf '%s' "$msg" | grep -qF "$out"; then echo "limit ${kb} KB: message does not name $out: $msg"; failed=$((failed + 1)); fi
    if printf '%s' "$msg" | grep -q '\.tmp-'; then echo "limit ${kb} KB: message names the temporary: $msg"; failed=$((failed + 1)); fi
    if ! cmp -s "$out" "$work/good.h5"; then echo "limit ${kb} KB: the old results file changed"; failed=$((failed + 1)); fi
  else
    if [ "$code" -ne 0 ]; then echo "limit ${kb} KB: exit $code for a file of ${size_kb} KB: $msg"; failed=$((failed + 1)); fi
    if ! "$exe" report "$out" > /dev/null; then echo "limit ${kb} KB: the new file does not read"; failed=$((failed + 1)); fi
    cp "$work/good.h5" "$out"
  fi
done
echo "$trials limits ($refused below the file's ${size_kb} KB), $failed problem(s)"
[ "$failed" -eq 0 ]
