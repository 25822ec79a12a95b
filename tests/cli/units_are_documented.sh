#!/usr/bin/env bash
# units_are_documented.sh RESULTS_MD RESULTS.h5...: every `units` attribute the results
# files hold is in docs/results.md's list of units (the row of `@units`), written as there.
# Needs h5dump (hdf5-tools); skipped (77) without it.
command -v h5dump >/dev/null || { echo "h5dump not installed: skipped"; exit 77; }
docs=$1
shift
list=$(grep -m1 '^| `@units` | attr |' "$docs")
[ -n "$list" ] || { echo "$docs: no row for @units"; exit 1; }
status=0
for results in "$@"; do
  units=$(h5dump -A "$results" | grep -A10 'ATTRIBUTE "units"' | sed -nE 's/.*\(0\): "(.*)"$/\1/p' | sort -u)
  [ -n "$units" ] || { echo "$results: no units read"; status=1; }
  while IFS= read -r unit; do
    if printf '%s\n' "$list" | grep -qF -- "\`$unit\`"; then
      echo "ok: $unit"
    else
      echo "$(basename "$docs"): the list of units lacks \`$unit\` ($results has it)"
      status=1
    fi
  done <<<"$units"
done
exit "$status"
