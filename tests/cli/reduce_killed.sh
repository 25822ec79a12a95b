#!/usr/bin/env bash
# reduce_killed.sh IMPACTLAB SESSION WORKDIR: `impactlab reduce` interrupted
# at any moment (SIGTERM, SIGINT after a range of delays) leaves either the
# earlier results file byte-identical or a complete new one that reads, and
# never a temporary. After a kill -9, which no program can clean up after, the
# next reduce removes the dead process's temporary.
set -u
set -m  # job control: background jobs keep SIGINT (otherwise they ignore it)
exe=$1 session=$2 work=$3
rm -rf "$work" && mkdir -p "$work" || exit 1
out=$work/results.h5
"$exe" reduce "$session" -o "$out" -q || { echo "setup: the first reduce failed"; exit 1; }
cp "$out" "$work/good.h5"
# How long one run takes, so the delays cover start, work, write and exit.
start=$(date +%s%N)
"$exe" reduce "$session" -o "$work/timing.h5" --fresh -q || exit 1
run_us=$(( ($(date +%s%N) - start) / 1000 ))
rm -f "$work/timing.h5"
pause_us() { sleep "$(($1 / 1000000)).$(printf '%06d' $(($1 % 1000000)))"; }
failed=0 trials=0 kept=0 replaced=0 signalled=0
for sig in TERM INT; do
  for step in 0 5 8 9 10 11 13; do
    cp "$work/good.h5" "$out"
    delay_us=$(( run_us * step / 10 ))
    "$exe" reduce "$session" -o "$out" --fresh -q 2> /dev/null &
    pid=$!
    pause_us "$delay_us"
    kill -s "$sig" "$pid" 2> /dev/null
    wait "$pid" 2> /dev/null
    [ $? -gt 128 ] && signalled=$((signalled + 1))
    trials=$((trials + 1))
    leftovers=$(find "$work" -name '*.tmp-*')
    if [ -n "$leftovers" ]; then echo "SIG$sig after ${delay_us} us: temporary left: $leftovers"; failed=$((failed + 1)); rm -f $leftovers; fi
    if cmp -s "$out" "$work/good.h5"; then
      kept=$((kept + 1))
    elif "$exe" report "$out" > /dev/null 2>&1; then
      replaced=$((replaced + 1))
    else
      echo "SIG$sig after ${delay_us} us: the results file is neither the old one nor a readable new one"
      failed=$((failed + 1))
    fi
  done
done
echo "$trials kills ($signalled ended by the signal): $kept left the old file, $replaced a complete new one, $failed problem(s)"

# kill -9: nothing runs in the process, so a temporary may stay. A dead
# process's temporary (here made by hand, with the pid of a finished job) is
# removed by the next write of the same output; a live process's is kept.
sleep 0 & dead=$!
wait "$dead"
printf 'partial' > "$out.tmp-$dead"
# Alive for as long as the checks take, however loaded the machine (it is
# killed below): with 5 s it could end first, its temporary then rightly
# removed as a dead process's.
sleep 300 & live=$!
printf 'partial' > "$out.tmp-$live"
for step in 5 9; do
  "$exe" reduce "$session" -o "$out" --fresh -q 2> /dev/null &
  pid=$!
  pause_us $(( run_us * step / 10 ))
  kill -9 "$pid" 2> /dev/null
  wait "$pid" 2> /dev/null
done
"$exe" reduce "$session" -o "$out" -q || { echo "reduce after kill -9 failed"; failed=$((failed + 1)); }
if [ -e "$out.tmp-$dead" ]; then echo "the dead process's temporary was not removed"; failed=$((failed + 1)); fi
if [ ! -e "$out.tmp-$live" ]; then echo "a live process's temporary was removed"; failed=$((failed + 1)); fi
kill "$live" 2> /dev/null
rm -f "$out.tmp-$live"
leftovers=$(find "$work" -name '*.tmp-*')
if [ -n "$leftovers" ]; then echo "after kill -9 and a new reduce: temporary left: $leftovers"; failed=$((failed + 1)); fi
echo "kill -9: stale temporary removed, live one kept: $([ "$failed" -eq 0 ] && echo yes || echo no)"
[ "$failed" -eq 0 ]
