#!/usr/bin/env bash
# progress_on_a_terminal.sh IMPACTLAB THESIS_SESSION OUT: on a terminal (script(1) gives the
# command one), reduce's progress line says what follows its last item (the fits across the
# runs, then writing the file) and synth counts its runs with the time left; in a pipe
# neither shows a progress line.
command -v script >/dev/null || {
  echo "no script(1) to give the command a terminal: skipped"
  exit 77
}
exe=$1 thesis=$2 out=$3
rm -rf "$out" && mkdir -p "$out" || exit 1
status=0
check() {  # check WHAT PATTERN TEXT
  if printf '%s\n' "$3" | grep -Eq -- "$2"; then echo "ok: $1"; else echo "FAILED: $1 (no match for $2)"; status=1; fi
}
# The line is rewritten with a carriage return: one line of text per state.
on_a_terminal() { script -qec "$1" /dev/null | tr '\r' '\n'; }

reduce=$(on_a_terminal "'$exe' reduce '$thesis' -o '$out/thesis.h5' --fresh")
printf '%s\n' "$reduce"
check "reduce counts the runs with the time left to measure" \
  '\[[1-7]/8\] [0-9]+\.[0-9] s, ~[0-9]+\.[0-9] s left to measure: run [0-9.]+ ok' "$reduce"
check "reduce says the fits across the runs follow the last run" \
  '\[8/8\] [0-9]+\.[0-9] s: run [0-9.]+ ok; fitting across the runs' "$reduce"
check "reduce says it writes the file" "[0-9]+\.[0-9] s: writing $out/thesis.h5" "$reduce"
check "reduce ends with its summary" '8 run\(s\): 8 ok' "$reduce"

synth=$(on_a_terminal "'$exe' synth -o '$out/quick' --preset quick --width 400")
printf '%s\n' "$synth"
check "synth counts its runs with the time left" \
  '\[1/2\] [0-9]+\.[0-9] s, ~[0-9]+\.[0-9] s left: run [^,]+, [0-9]+ photo\(s\)' "$synth"

piped=$("$exe" reduce "$thesis" -o "$out/piped.h5" --fresh 2>&1 | cat)
printf '%s\n' "$piped"
if printf '%s\n' "$piped" | grep -Eq '\[[0-9]+/[0-9]+\]|writing'; then
  echo "FAILED: a progress line in a pipe"
  status=1
fi
exit "$status"
