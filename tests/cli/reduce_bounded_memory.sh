#!/usr/bin/env bash
# reduce_bounded_memory.sh IMPACTLAB WORKDIR CASE: issue 14, item 3, as a user
# meets it. A generated quick session (photo runs, a CSV run, a typed-in run)
# with one run's time axis wrong by CASE:
#   photo-1e8    a photo run's right trace: time_per_div = 1e8
#   photo-1e300  the same with 1e300
#   csv-ns       the CSV run's right trace: time column in nanoseconds
# is reduced under a 4 GB address-space limit. Passes when reduce finishes
# within 60 s (it once took 108 s and 16.9 GB to fail with bad_alloc) with
# exit 1 (some runs failed), the bad run's message naming the key or file and
# the pendulum's swings, and every other run reduced.
set -u
exe=$1 work=$2 case=$3
dir=$work/bounded-$case
rm -rf "$dir" && mkdir -p "$dir" || exit 1
"$exe" synth --out "$dir/s" --preset quick --csv-run --typed-run >/dev/null 2>&1 ||
  { echo "synth failed"; exit 1; }
manifest=$dir/s/session.toml
case $case in
  photo-1e8 | photo-1e300)
    value=${case#photo-}
    # The first [run.traces.right] without a csv: a photo run's rebounds trace.
    awk -v value="$value" '
      /^\[/ { in_right = ($0 == "[run.traces.right]"); has_csv = 0 }
      in_right && /^csv = / { has_csv = 1 }
      in_right && !has_csv && !done && /^time_per_div = / { print "time_per_div = " value; done = 1; next }
      { print }' "$manifest" >"$manifest.new" && mv "$manifest.new" "$manifest"
    expected='traces\.right\.time_per_div.*swings out and back of this pendulum'
    ;;
  csv-ns)
    csv=$(awk '/^\[run\.traces\.right\]/ { r = 1; next } /^\[/ { r = 0 } r && /^csv = / { gsub(/"/, "", $3); print $3; exit }' "$manifest")
    [ -n "$csv" ] || { echo "no CSV run in the session"; exit 1; }
    awk -F, 'NR == 1 { print; next } { printf "%.12g,%s\n", $1 * 1e9, $2 }' "$dir/s/$csv" >"$dir/ns.csv" &&
      mv "$dir/ns.csv" "$dir/s/$csv"
    expected="$(basename "$csv").*swings out and back of this pendulum"
    ;;
  *) echo "unknown case $case"; exit 1 ;;
esac
grep -q "1e300\|1e8" "$manifest" || [ "$case" = csv-ns ] || { echo "the edit did not apply"; exit 1; }

# GNU time reports the peak memory where it is installed.
measure=()
[ -x /usr/bin/time ] && measure=(/usr/bin/time -f 'peak resident memory %M kB')
start=$(date +%s%N)
output=$( (ulimit -v 4000000 && timeout 60 "${measure[@]}" "$exe" reduce "$dir/s" -o "$dir/out.h5" -j 2) 2>&1)
code=$?
printf '%s\nexit %s after %s ms\n' "$output" "$code" $((($(date +%s%N) - start) / 1000000))
[ "$code" -eq 1 ] || { echo "expected exit 1 (some runs failed), got $code"; exit 1; }
printf '%s\n' "$output" | grep -Eq -- "$expected" || { echo "no message matching: $expected"; exit 1; }
# Four runs, one failed: the other three reduced.
printf '%s\n' "$output" | grep -Eq -- "4 run\(s\): 3 ok" || { echo "the other runs did not reduce"; exit 1; }
