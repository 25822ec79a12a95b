#!/usr/bin/env bash
# workflow_reduces_what_changed.sh IMPACTLAB SNAKEFILE WORKDIR: the archive
# workflow (workflow/Snakefile) on a generated campaign of 4 sessions, as a
# user runs it with --cores 2:
# - the first run reduces every session (one job each) and writes a results
#   file per session (and the campaign, when impactlab has that command);
# - a second run reduces nothing and leaves every results file as it was;
# - touching a manifest without changing it reduces nothing either;
# - editing one manifest reduces that session only, and only its results file
#   changes.
# Skipped (77) when snakemake is not installed.
set -u
exe=$1 snakefile=$2 work=$3
command -v snakemake >/dev/null || { echo "snakemake not installed: skipped"; exit 77; }
dir=$work/workflow-reduces
rm -rf "$dir" && mkdir -p "$dir" || exit 1
"$exe" synth-campaign -o "$dir/archive" --sessions 4 --seed 3 >/dev/null 2>&1 ||
  { echo "synth-campaign failed"; exit 1; }
results=$dir/results
# With impactlab's campaign command the whole workflow runs, else its reduce part.
target=reduced
"$exe" campaign --help >/dev/null 2>&1 && target=all
fail() { echo "$1"; printf '%s\n' "$output"; exit 1; }
run() {
  output=$(snakemake -s "$snakefile" --directory "$dir" --cores 2 --scheduler greedy "$target" \
    --config root="$dir/archive" output="$results" impactlab="$exe" 2>&1) ||
    fail "snakemake failed"
}
# The sessions the last run reduced, one per line.
reduced() { printf '%s\n' "$output" | sed -n 's/^ *wildcards: session=//p' | sort; }
# Each results file's inode and modification time: a rewrite changes them.
stamps() { for f in "$results"/*.h5; do stat -c '%n %i %Y.%y' "$f"; done; }

run
[ "$(reduced | wc -l)" -eq 4 ] || fail "the first run did not reduce the 4 sessions"
for s in "$dir"/archive/*/; do
  name=$(basename "$s")
  [ -s "$results/$name.h5" ] || fail "no results file for $name"
done
[ "$target" = reduced ] || [ -s "$results/campaign.h5" ] || fail "no campaign file"
before=$(stamps)

run
[ -z "$(reduced)" ] || fail "the second run reduced $(reduced)"
[ "$(stamps)" = "$before" ] || fail "the second run rewrote a results file"

sleep 1  # a newer modification time than the results files'
touch "$dir"/archive/*/session.toml
run
[ -z "$(reduced)" ] || fail "touching the manifests reduced $(reduced)"
[ "$(stamps)" = "$before" ] || fail "touching the manifests rewrote a results file"

edited=$(basename "$(ls -d "$dir"/archive/*/ | sed -n 2p)")
sed -i 's/^title = "/title = "edited: /' "$dir/archive/$edited/session.toml"
run
[ "$(reduced)" = "$edited" ] || fail "editing $edited reduced: $(reduced)"
# Of the sessions' results, only the edited one's is rewritten (the campaign,
# built from all of them, is rebuilt).
changed=$(diff <(printf '%s\n' "$before") <(stamps) | sed -n 's/^> \([^ ]*\) .*/\1/p' |
  grep -v "/campaign\.h5$")
[ "$changed" = "$results/$edited.h5" ] || fail "editing $edited changed: $changed"
echo "4 sessions reduced; again: none; touched: none; $edited edited: $edited alone"
