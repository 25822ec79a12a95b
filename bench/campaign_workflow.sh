#!/usr/bin/env bash
# campaign_workflow.sh IMPACTLAB [SESSIONS|ARCHIVE [CORES]]: the archive
# workflow (workflow/Snakefile) on a generated campaign (default 100 sessions,
# 2 cores), or on a copy of an archive folder of sessions, against the
# sessions' own reduce times (docs/campaigns.md).
# Prints, in wall time and in CPU time (user + system, the processes' own and
# their children's):
# - the sum of the sessions' reduce times, each reduced alone with -j 1;
# - the workflow with --cores CORES on the fresh archive: its wall time
#   against that sum divided by CORES (the issue's target: within 5 %), its
#   CPU time against the sum (what the workflow itself adds);
# - a second run (nothing changed), and a run after one session's manifest
#   was edited: how many sessions each reduced, and its times;
# - the load average before and after: on a shared machine the wall times
#   include the other processes' share of the cores, the CPU times do not.
# Needs snakemake and GNU time (/usr/bin/time). Removes its temporary folder.
set -euo pipefail
exe=$(realpath "$1") sessions=${2:-100} cores=${3:-2}
here=$(dirname "$(realpath "$0")")
snakefile=$here/../workflow/Snakefile
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
load() { cut -d' ' -f1-3 /proc/loadavg; }
load_before=$(load)

if [ -d "$sessions" ]; then
  cp -r "$sessions" "$work/archive"
  sessions=$(find "$work/archive" -name session.toml | wc -l)
else
  "$exe" synth-campaign -o "$work/archive" --sessions "$sessions" --seed 100 2>/dev/null
fi

# Each session reduced alone, one after another: the work the workflow shares out.
for s in $(find "$work/archive" -name session.toml -printf '%h\n' | sort); do
  /usr/bin/time -f '%e %U %S' -a -o "$work/alone.times" \
    "$exe" reduce "$s" -o "$work/alone.h5" -j 1 -q --fresh 2>/dev/null || [ $? -eq 1 ]
done
read -r sum_wall sum_cpu < <(awk '{ w += $1; c += $2 + $3 } END { print w, c }' "$work/alone.times")

# One workflow run: sets wall, cpu (snakemake and its jobs) and reduced (sessions).
workflow() {
  /usr/bin/time -f '%e %U %S' -o "$work/workflow.time" \
    snakemake -s "$snakefile" --directory "$work" --cores "$cores" --scheduler greedy reduced \
    --config root="$work/archive" output="$work/results" impactlab="$exe" >"$work/workflow.log" 2>&1
  read -r wall cpu < <(awk '{ print $1, $2 + $3 }' "$work/workflow.time")
  reduced=$(grep -c '^ *wildcards: session=' "$work/workflow.log" || true)
}

workflow
fresh_wall=$wall fresh_cpu=$cpu fresh_reduced=$reduced
workflow
again_wall=$wall again_cpu=$cpu again_reduced=$reduced
edited=$(find "$work/archive" -name session.toml | sort | sed -n 2p)
sed -i '1i # edited' "$edited"
workflow
edit_wall=$wall edit_cpu=$cpu edit_reduced=$reduced

ratio() { echo "$1 / ($2 / $cores)" | bc -l; }
printf '%d sessions, %d cores; load average %s before, %s after\n' "$sessions" "$cores" \
  "$load_before" "$(load)"
printf '%-40s %9s %9s\n' "" "wall (s)" "CPU (s)"
printf '%-40s %9.2f %9.2f\n' "sum of the sessions' reduces" "$sum_wall" "$sum_cpu"
printf '%-40s %9.2f %9.2f\n' "that sum / $cores" "$(echo "$sum_wall / $cores" | bc -l)" \
  "$(echo "$sum_cpu / $cores" | bc -l)"
printf '%-40s %9.2f %9.2f\n' "workflow, fresh: $fresh_reduced reduced" "$fresh_wall" "$fresh_cpu"
# Wall time against the sum shared by the cores; CPU time against the sum itself
# (what Snakemake, its job shells and the hard links add).
printf '%-40s %9.3f %9.3f\n' "  ratio (wall: to sum / $cores; CPU: to sum)" \
  "$(ratio "$fresh_wall" "$sum_wall")" "$(echo "$fresh_cpu / $sum_cpu" | bc -l)"
printf '%-40s %9.2f %9.2f\n' "workflow, nothing changed: $again_reduced reduced" "$again_wall" \
  "$again_cpu"
printf '%-40s %9.2f %9.2f\n' "workflow, one edited: $edit_reduced reduced" "$edit_wall" "$edit_cpu"
