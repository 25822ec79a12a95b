#!/usr/bin/env bash
# docs_match_help.sh IMPACTLAB DOCS_FOLDER README [RESULTS.h5...]: the docs agree with the
# command line.
# - Every option a command's --help lists is named in its section of docs/commands.md (but its
#   stage settings, which the page gives as `--KEY VALUE` and settings.md lists one by one).
# - Every option a section of docs/commands.md names is in the --help of its command(s).
# - Every command line a page writes (`impactlab reduce ... --fresh`, `reduce --fresh`) uses
#   options its command has.
# - Every table `impactlab report` makes of the RESULTS files is in docs/commands.md's list
#   (a log's or a prediction's with its id as `ID`, `T`, `S`).
set -u
exe=$1 docs=$2 readme=$3
shift 3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
fail() {
  echo "$*"
  status=1
}

# A help text's subcommands, and its options: all (for what the docs name) and all but the
# stage settings (what commands.md must name).
subcommands() { awk '/^Subcommands:/ {on = 1; next} on && /^  [a-z]/ {sub(",", "", $1); print $1}'; }
options() {
  awk -v all="$1" '
    /^[A-Z].*:$/ { stage = ($0 ~ /^Stage settings/) }
    /^  -/ && (all || !stage) {
      n = split($1, names, ",")
      for (i = 1; i <= n; ++i) if (names[i] ~ /^--/) { sub(/\{.*/, "", names[i]); print names[i] }
    }'
}

# Every command as "word" or "word sub", with its options in $work/<command>.all and .documented.
commands=()
for word in $("$exe" help | subcommands); do
  [ "$word" = help ] && continue
  subs=$("$exe" "$word" --help | subcommands)
  if [ -z "$subs" ]; then
    commands+=("$word")
  else
    for sub in $subs; do commands+=("$word $sub"); done
  fi
done
for command in "${commands[@]}"; do
  # shellcheck disable=SC2086 # the command's words
  help=$("$exe" $command --help) || fail "$command --help failed"
  file=$work/${command// /_}
  printf '%s\n' "$help" | options 1 | sort -u >"$file.all"
  printf '%s\n' "$help" | options 0 | sort -u >"$file.documented"
done

# docs/commands.md's section of a command: its heading, "## `impactlab WORD SUB|SUB ...", to
# the next heading of that level.
section() {
  awk -v word="$1" -v sub_="$2" '
    /^## / {
      on = 0
      if ($2 != "`impactlab") next
      w1 = $3; gsub("`", "", w1)
      w2 = $4; gsub("`", "", w2)
      if (w1 != word) next
      if (sub_ == "") on = 1
      n = split(w2, alternatives, "|")
      for (i = 1; i <= n; ++i) if (alternatives[i] == sub_) on = 1
    }
    on' "$docs/commands.md"
}
named() { grep -oE -- '--[a-z][a-z0-9._-]*' | sed 's/[-]*$//' | sort -u; }

# Forward: each command's options are in its section.
declare -A section_flags section_commands
for command in "${commands[@]}"; do
  read -r word sub <<<"$command"
  text=$(section "$word" "${sub:-}")
  if [ -z "$text" ]; then
    fail "docs/commands.md: no section for \`impactlab $command\`"
    continue
  fi
  file=$work/${command// /_}
  while read -r flag; do
    [ "$flag" = --help ] && continue
    printf '%s\n' "$text" | grep -qE -- "$flag([^a-z0-9_-]|\\.[^a-z]|\\.?\$)" ||
      fail "docs/commands.md: \`impactlab $command\` has $flag (its --help lists it) but its section does not name it"
  done <"$file.documented"
  key=$(printf '%s\n' "$text" | head -c 200 | md5sum | cut -d' ' -f1)
  section_commands[$key]+="$command;"
  section_flags[$key]=$(printf '%s\n' "$text" | named)
done

# Backward: what a section names is an option of one of its commands (`--products.KEY` of
# one whose name starts so).
for key in "${!section_commands[@]}"; do
  IFS=';' read -ra owners <<<"${section_commands[$key]}"
  : >"$work/union"
  for command in "${owners[@]}"; do cat "$work/${command// /_}.all" >>"$work/union"; done
  while read -r flag; do
    [ -z "$flag" ] && continue
    grep -qxF -- "$flag" "$work/union" && continue
    grep -qxF -- "${flag%.}" "$work/union" && continue  # a sentence's full stop
    case $flag in *.) grep -qF -- "$flag" "$work/union" && continue ;; esac
    fail "docs/commands.md: the section of \`impactlab ${owners[0]}\` names $flag, which its --help does not list"
  done <<<"${section_flags[$key]}"
done

# Every page: a command line's options are its command's, but the mistakes commands.md shows
# with their answers.
list=$(printf '%s;' "${commands[@]}")
for page in "$docs"/*.md "$readme"; do
  awk -v dir="$work" -v list="$list" -v page="$(basename "$page")" \
      -v mistyped=" --outptu --reuse --digitize.traces.methd " '
    BEGIN {
      n = split(list, commands, ";")
      for (i = 1; i <= n; ++i) {
        if (commands[i] == "") continue
        split(commands[i], w, " ")
        top[w[1]] = 1
        file = dir "/" commands[i] ".all"
        gsub(" ", "_", file)
        while ((getline flag < file) > 0) {
          has[commands[i], flag] = 1       # the command itself
          has[w[1] " *", flag] = 1         # any subcommand of its word (`pendul fit|response`)
        }
        close(file)
      }
    }
    {
      # Pieces of a line between backticks and between commands joined by && or ;.
      m = split($0, pieces, /`|&&|;/)
      for (p = 1; p <= m; ++p) {
        piece = pieces[p]
        sub(/^ +/, "", piece)
        # Prose names commands too ("reduce reads it"): a command line starts with the
        # command, or names impactlab before it.
        at = index(piece, "impactlab ")
        rest = at ? substr(piece, at + 10) : piece
        split(rest, w, " ")
        if (!(w[1] in top)) continue
        command = (w[1] " " w[2])
        if (!((command, "--help") in has)) command = ((w[1], "--help") in has) ? w[1] : w[1] " *"
        while (match(rest, /--[a-z][a-z0-9._-]*/)) {
          flag = substr(rest, RSTART, RLENGTH)
          rest = substr(rest, RSTART + RLENGTH)
          sub(/-+$/, "", flag)
          if (index(mistyped, " " flag " ") || ((command, flag) in has)) continue
          known = 0
          if (flag ~ /\.$/) {  # `--products.KEY`, or a full stop
            if ((command, substr(flag, 1, length(flag) - 1)) in has) known = 1
            for (key in has) {
              split(key, parts, SUBSEP)
              if (parts[1] == command && index(parts[2], flag) == 1) known = 1
            }
          }
          if (!known) printf "%s:%d: `%s` has no option %s\n", page, NR, command, flag
        }
      }
    }' "$page"
done | tee "$work/pages"
[ -s "$work/pages" ] && status=1

# The tables.
for results in "$@"; do
  list=$("$exe" report "$results" --table no-such-table 2>&1 | sed -n 's/.*its tables are: //p')
  [ -z "$list" ] && fail "report $results --table no-such-table does not list the tables"
  for table in ${list//,/ }; do
    generic=$(printf '%s\n' "$table" |
      sed -E 's/^table4_prediction_.*_from_.*$/table4_prediction_T_from_S/; s/^log_.*_(impact|notes)$/log_ID_\1/; t; s/^log_.*$/log_ID/')
    grep -qF -- "\`$generic\`" "$docs/commands.md" ||
      fail "docs/commands.md: the table list lacks \`$generic\` (report $results makes $table)"
  done
done
[ "$status" -eq 0 ] && echo "the docs name every option and table of ${#commands[@]} commands"
exit "$status"
