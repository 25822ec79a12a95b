#!/usr/bin/env bash
# workflow_on_slurm.sh IMPACTLAB SNAKEFILE PROFILE WORKDIR: the archive workflow
# through Snakemake's Slurm support (--profile workflow/profiles/slurm), as
# docs/campaigns.md shows it, on a machine without Slurm: stand-ins
# for sbatch, sacct, sinfo and srun run each submitted job at once on this
# machine and report it COMPLETED. Checks that every session is submitted as
# a job of its own with the rule's resources (-t 10 --mem 1000
# --cpus-per-task=1), that each job reduces its session, and that a second
# run submits nothing. Skipped (77) when snakemake is not installed.
# --max-status-checks-per-second 1: the Slurm executor sleeps 1/rate between
# its rounds of asking sacct for the jobs' states, and takes any rate above 1
# as its default, one round per 33 s (Snakemake 7.21's scheduler.py), which
# made this test take 100 s; at 1 it takes a few seconds.
set -u
exe=$1 snakefile=$2 profile=$3 work=$4
command -v snakemake >/dev/null || { echo "snakemake not installed: skipped"; exit 77; }
dir=$work/workflow-on-slurm
rm -rf "$dir" && mkdir -p "$dir/bin" "$dir/jobs" || exit 1
"$exe" synth-campaign -o "$dir/archive" --sessions 2 --seed 4 >/dev/null 2>&1 ||
  { echo "synth-campaign failed"; exit 1; }

# sbatch ... -o LOG -D DIR --wrap=CMD: runs CMD in DIR in the background.
cat >"$dir/bin/sbatch" <<STANDIN
#!/usr/bin/env bash
echo "\$*" >>"$dir/sbatch.calls"
id=\$(( \$(ls "$dir/jobs" | wc -l) + 1 )); touch "$dir/jobs/\$id"
log=/dev/null folder=. previous=
for a in "\$@"; do
  case "\$a" in --wrap=*) command=\${a#--wrap=} ;; esac
  [ "\$previous" = -o ] && log=\${a//%j/\$id}
  [ "\$previous" = -D ] && folder=\$a
  previous=\$a
done
( cd "\$folder" && bash -c "\$command" >"\$log" 2>&1; echo \$? >"$dir/jobs/\$id.rc" ) &
echo "Submitted batch job \$id"
STANDIN
# sacct ... -j ID: the job's state.
cat >"$dir/bin/sacct" <<STANDIN
#!/usr/bin/env bash
id= previous=
for a in "\$@"; do [ "\$previous" = -j ] && id=\$a; previous=\$a; done
[ -n "\$id" ] || exit 0
if [ ! -f "$dir/jobs/\$id.rc" ]; then echo "\$id|RUNNING"
elif [ "\$(cat "$dir/jobs/\$id.rc")" = 0 ]; then echo "\$id|COMPLETED"
else echo "\$id|FAILED"; fi
STANDIN
printf '#!/bin/sh\necho PARTITION; echo "debug*"\n' >"$dir/bin/sinfo"
# srun -n1 --cpu-bind=q COMMAND...: the job step, here.
printf '#!/bin/sh\nshift 2\nexec "$@"\n' >"$dir/bin/srun"
chmod +x "$dir"/bin/*

fail() { echo "$1"; printf '%s\n' "$output"; exit 1; }
run() {
  output=$(cd "$dir" && PATH="$dir/bin:$PATH" USER=${USER:-$(id -un)} snakemake -s "$snakefile" \
    --profile "$profile" --max-status-checks-per-second 1 reduced \
    --config root="$dir/archive" output="$dir/results" impactlab="$exe" 2>&1) ||
    fail "snakemake failed"
}
run
[ "$(grep -c -- '-t 10 --mem 1000 --cpus-per-task=1' "$dir/sbatch.calls")" -eq 2 ] ||
  fail "not one job per session with the rule's resources: $(cat "$dir/sbatch.calls")"
for s in "$dir"/archive/*/; do
  name=$(basename "$s")
  grep -q "reduce:session=$name'" "$dir/sbatch.calls" || fail "no job for $name"
  [ -s "$dir/results/$name.h5" ] || fail "no results file for $name"
done
run
[ "$(wc -l <"$dir/sbatch.calls")" -eq 2 ] || fail "the second run submitted jobs"
echo "2 sessions, 2 Slurm jobs; again: none"
