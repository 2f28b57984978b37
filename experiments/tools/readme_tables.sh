#!/usr/bin/env bash
# README.md's generated tables: replaces the lines between each marker pair
#   <!-- BEGIN name -->
#   <!-- END name -->
# with the body of the matching "## " section (up to the next "## " or "# "
# heading, blank lines at either end trimmed) of results/summary.md, which
# experiments/tools/summarize.sh writes, or of LIST.md, a file with "## methods" and
# "## scenes" sections (nhi list --markdown).
#
#   experiments/tools/readme_tables.sh [--readme FILE] SUMMARY.md [LIST.md]
#
# Without LIST.md the methods and scenes pairs are left as they are.  Fails (exit
# 1, README untouched) when a pair below is missing from the README, a marker is
# unknown, unpaired or nested, or a section is missing, empty or ambiguous; exit
# 2 on a bad command line.  The README is rewritten through a temporary file in
# its directory and a rename, and only when something changed: a second run
# changes nothing.
set -euo pipefail

# marker name | source (summary or list) | heading: "## " followed by this text,
# then the end of the line, " (" or ":"
SECTIONS='
which-method-when|summary|Which method when, by scene class
paper-figures|summary|Paper scenes at h = 0.2
step-cost-ratios|summary|Step cost ratios
methods|list|methods
scenes|list|scenes
'

die() { echo "readme_tables: $*" >&2; exit 1; }
usage() { echo "usage: $0 [--readme FILE] SUMMARY.md [LIST.md]" >&2; exit 2; }

readme=README.md
args=()
while [ $# -gt 0 ]; do
  case $1 in
    --readme) [ $# -ge 2 ] || usage; readme=$2; shift 2 ;;
    -h|--help) usage ;;
    -*) usage ;;
    *) args+=("$1"); shift ;;
  esac
done
[ ${#args[@]} -ge 1 ] && [ ${#args[@]} -le 2 ] || usage
summary=${args[0]}
list=${args[1]:-}
[ -f "$readme" ] || die "$readme: no such file"
[ -f "$summary" ] || die "$summary: no such file"
[ -z "$list" ] || [ -f "$list" ] || die "$list: no such file"

work=$(mktemp -d)
tmp=""
trap 'rm -rf "$work"; [ -z "$tmp" ] || rm -f "$tmp"' EXIT
trap 'exit 130' INT TERM

# The README's markers, in order, checked: each known, paired once, not nested.
known=$(printf '%s\n' "$SECTIONS" | awk -F'|' 'NF == 3 { print $1 }')
awk -v known="$known" '
  BEGIN { n = split(known, k, "\n"); for (i = 1; i <= n; i++) ok[k[i]] = 1 }
  /^<!-- (BEGIN|END) [^ ]+ -->[ \t]*$/ {
    kind = $2; name = $3
    if (!(name in ok)) { printf "%s:%d: unknown marker %s\n", FILENAME, FNR, name > "/dev/stderr"; bad = 1; next }
    if (kind == "BEGIN") {
      if (open != "") { printf "%s:%d: BEGIN %s inside %s\n", FILENAME, FNR, name, open > "/dev/stderr"; bad = 1 }
      if (name in seen) { printf "%s:%d: second BEGIN %s\n", FILENAME, FNR, name > "/dev/stderr"; bad = 1 }
      seen[name] = 1; open = name
    } else {
      if (open != name) { printf "%s:%d: END %s without its BEGIN\n", FILENAME, FNR, name > "/dev/stderr"; bad = 1 }
      open = ""; print name
    }
  }
  END { if (open != "") { printf "%s: BEGIN %s without its END\n", FILENAME, open > "/dev/stderr"; bad = 1 }
        exit bad }' "$readme" > "$work/markers" || die "$readme: bad markers"

# One body file per pair to fill.
while IFS='|' read -r name source heading; do
  [ -n "$name" ] || continue
  if [ "$source" = list ]; then
    [ -n "$list" ] || continue
    file=$list
  else
    file=$summary
  fi
  grep -qxF "$name" "$work/markers" || die "$readme: no marker pair <!-- BEGIN $name --> ... <!-- END $name -->"
  awk -v h="## $heading" -v out="$work/$name.body" -v count="$work/$name.count" '
    function is_heading(line) { return line ~ /^##? / }
    function matches(line) {
      if (index(line, h) != 1) return 0
      rest = substr(line, length(h) + 1)
      return rest == "" || rest ~ /^( \(|:)/
    }
    is_heading($0) { inside = matches($0); if (inside) n++; next }
    inside && n == 1 { body[++m] = $0 }
    END {
      first = 1; while (first <= m && body[first] ~ /^[ \t]*$/) first++
      last = m; while (last >= first && body[last] ~ /^[ \t]*$/) last--
      for (i = first; i <= last; i++) print body[i] > out
      print n + 0 > count
    }' "$file"
  n=$(cat "$work/$name.count")
  [ "$n" -ge 1 ] || die "$file: no section \"## $heading\" (for <!-- BEGIN $name -->)"
  [ "$n" -eq 1 ] || die "$file: $n sections \"## $heading\" (for <!-- BEGIN $name -->)"
  [ -s "$work/$name.body" ] || die "$file: section \"## $heading\" is empty"
done <<< "$SECTIONS"

# The new README: each pair with a body gets BEGIN, a blank line, the body, a
# blank line, END; everything else as it was.
tmp=$(mktemp "$(dirname "$readme")/.readme_tables.XXXXXX")
awk -v dir="$work" '
  /^<!-- BEGIN [^ ]+ -->[ \t]*$/ {
    f = dir "/" $3 ".body"
    if ((getline line < f) > 0) {
      print; print ""; print line
      while ((getline line < f) > 0) print line
      close(f); print ""; skip = $3; next
    }
  }
  skip != "" && /^<!-- END [^ ]+ -->[ \t]*$/ && $3 == skip { skip = ""; print; next }
  skip == "" { print }' "$readme" > "$tmp"

if cmp -s "$tmp" "$readme"; then
  echo "readme_tables: $readme unchanged"
else
  chmod --reference="$readme" "$tmp"
  mv -f "$tmp" "$readme"
  tmp=""
  echo "readme_tables: $readme updated"
fi
