#!/usr/bin/env bash
# reduce_bad_entry.sh IMPACTLAB THESIS_SESSION LOGS_SESSION WORKDIR: one bad
# manifest entry fails alone (issue 14, item 2). For each mistake, a copy of
# the thesis session (eight typed-in runs) gets one more [[run]] with that
# mistake; `impactlab reduce` must exit 1, write the results file with the
# eight good runs and the bad one failed, and name the manifest and the key.
# A named pipe given as the photo must not make reduce wait. A bad channel in
# one of two logs fails that log alone.
set -u
exe=$1 thesis=$2 logs=$3 work=$4
rm -rf "$work" && mkdir -p "$work" || exit 1
outside=$work/outside
mkdir -p "$outside" && echo secret >"$outside/secret.jpg"
failures=0 cases=0

# check NAME EXPECTED_PATTERN: reduces $dir and checks the outcome.
check() {
  local name=$1 pattern=$2 output code
  cases=$((cases + 1))
  output=$(timeout 60 "$exe" reduce "$dir" -o "$work/$name.h5" 2>&1)
  code=$?
  local ok=1
  [ "$code" -eq 1 ] || { echo "[$name] expected exit 1, got $code"; ok=0; }
  [ -s "$work/$name.h5" ] || { echo "[$name] no results file"; ok=0; }
  printf '%s\n' "$output" | grep -Eq -- "$pattern" || { echo "[$name] no match for: $pattern"; ok=0; }
  printf '%s\n' "$output" | grep -Eq -- "run\(s\): 8 ok" || { echo "[$name] the good runs did not reduce"; ok=0; }
  if [ "$ok" -eq 0 ]; then printf '%s\n' "$output"; failures=$((failures + 1)); fi
}

# session NAME RUN_TOML: a copy of the thesis session with RUN_TOML appended.
session() {
  dir=$work/$1
  cp -r "$thesis" "$dir" && mkdir -p "$dir/runs" && printf '\n%s\n' "$2" >>"$dir/session.toml"
}

photo_run() {  # photo_run PHOTO [TIME_PER_DIV]
  printf '[[run]]\nid = "bad"\ninitial_displacement = 0.3\nphoto = %s\n[run.traces.right]\ntime_per_div = %s\nvolts_per_div = 0.2\n' "$1" "${2:-0.5}"
}
typed_run() {  # typed_run X0 [EXTRA]
  printf '[[run]]\nid = "bad"\ninitial_displacement = %s\nrebounds = [0.2, 0.1]\n%s\n' "$1" "${2:-}"
}

session missing-photo "$(photo_run '"runs/missing.jpg"')"
check missing-photo 'session\.toml:[0-9]+: run "bad"\.photo: expected an existing file'
session dotdot "$(photo_run '"../secret.jpg"')"
check dotdot 'run "bad"\.photo: .*uses '"'"'\.\.'"'"
session absolute "$(photo_run "\"$outside/secret.jpg\"")"
check absolute 'run "bad"\.photo: expected a path relative to the session folder'
session symlink "$(photo_run '"runs/link.jpg"')"
ln -s "$outside/secret.jpg" "$dir/runs/link.jpg"
check symlink 'run "bad"\.photo: .*outside it through a symbolic link'
session folder "$(photo_run '"runs/folder.jpg"')"
mkdir -p "$dir/runs/folder.jpg"
check folder 'run "bad"\.photo: expected a file, found a folder'
session fifo "$(photo_run '"runs/pipe.jpg"')"
mkfifo "$dir/runs/pipe.jpg"
check fifo 'run "bad"\.photo: expected a regular file, found a named pipe'
session wrong-type "$(typed_run '"abc"')"
check wrong-type 'run "bad"\.initial_displacement: expected a positive displacement X0 \(in\), found string "abc"'
session nan "$(typed_run nan)"
check nan 'run "bad"\.initial_displacement: .*not a finite number'
session inf "$(typed_run 0.3 'contact_time = inf')"
check inf 'run "bad"\.contact_time: .*not a finite number'
session zero-time "$(photo_run '"runs/a.jpg"' 0)"
: >"$dir/runs/a.jpg"
check zero-time 'run "bad"\.traces\.right\.time_per_div: expected a positive number of s/div, found 0'
session duplicate "$(typed_run 0.3 | sed 's/"bad"/"0.234"/')"
check duplicate 'run "0\.234"\.id: expected an id no other run has'
session unknown-calibration "$(typed_run 0.3 'calibration = { right = "R-9" }')"
check unknown-calibration 'run "bad"\.calibration\.right: .*found "R-9", which no calibration has'
session unsafe-id "$(typed_run 0.3 | sed 's/"bad"/"a\/b"/')"
check unsafe-id 'run "a/b"\.id: expected a run id \(a string\) of 1 to 64 letters'
session too-long-x0 "$(typed_run 1e6)"
check too-long-x0 'run "bad"\.initial_displacement: expected a displacement X0 between .* and 22 in'

# A bad channel in one of two logs: the other log is analysed.
cases=$((cases + 1))
dir=$work/bad-log
cp -r "$logs" "$dir"
printf '\n[[log]]\nid = "second"\nexperiment = "logs/case1-experiment.csv"\n[log.channels]\nq1 = { column = "enc1", counts_per_rev = "many" }\n' >>"$dir/session.toml"
output=$(timeout 60 "$exe" reduce "$dir" -o "$work/bad-log.h5" 2>&1)
code=$?
if [ "$code" -ne 1 ] || [ ! -s "$work/bad-log.h5" ] ||
  ! printf '%s\n' "$output" | grep -q 'log second failed: .*log "second"\.channels\.q1\.counts_per_rev' ||
  ! printf '%s\n' "$output" | grep -q '2 log(s): 1 failed'; then
  echo "[bad-log] exit $code"; printf '%s\n' "$output"; failures=$((failures + 1))
fi

echo "bad entries: $((cases - failures)) of $cases cases held"
[ "$failures" -eq 0 ]
