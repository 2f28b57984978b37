#!/usr/bin/env bash
# experiments/tools/compare_results.cpp on two tiny result trees: a row inserted in
# the middle of a labelled method list is one new entry, not a difference in
# every later row; a number changed in a later row is the one difference (exit
# 1); the same tree against itself agrees (exit 0); an unlabelled array stays
# positional (a longer one is structural); --ignore-key takes a shell pattern
# (it skips every key it matches, and only those).
set -uo pipefail
compare=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
mkdir -p "$tmp/old" "$tmp/new"
cat > "$tmp/old/study.json" << 'EOF'
{"meta": {"time_utc": "then"},
 "scenes": {"particle": {"h": [0.1, 0.05], "methods": [
   {"label": "dla a=0.5", "order": 2, "error": [1e-3, 2.5e-4]},
   {"label": "rk4", "order": 4, "error": [1e-5, 6.25e-7]},
   {"label": "mp06", "order": 2, "error": [2e-3, 5e-4]}]}}}
EOF
cat > "$tmp/new/study.json" << 'EOF'
{"meta": {"time_utc": "now"},
 "scenes": {"particle": {"h": [0.1, 0.05], "methods": [
   {"label": "dla a=0.5", "order": 2, "error": [1e-3, 2.5e-4]},
   {"label": "spark", "order": 2, "error": [3e-3, 7.5e-4]},
   {"label": "rk4", "order": 4, "error": [1e-5, 6.25e-7]},
   {"label": "mp06", "order": 2, "error": [2e-3, 5.5e-4]}]}}}
EOF
fails=0
fail() { echo "FAIL: $*"; fails=1; }

out=$("$compare" "$tmp/old" "$tmp/new" 2>&1); rc=$?
echo "$out"
[ "$rc" -eq 1 ] || fail "inserted row and changed number: exit $rc, expected 1"
grep -q '^study.json: 11 numbers, max rel diff 0.0909 at scenes.particle.methods\[label=mp06\].error\[1\] (old 0.000500*1, new 0.000550*3), 1 above tol; 0 structural, 0 text differences; 1 new, 0 gone entries  \[> tol\]$' <<< "$out" ||
  fail "not one difference at mp06's error[1] and one new entry"
[ "$(grep -c '^    new: ' <<< "$out")" -eq 1 ] && grep -q '^    new: scenes.particle.methods\[label=spark\]$' <<< "$out" ||
  fail "the new entry is not listed as spark's"
grep -q '^    \(structural\|text\|gone\): ' <<< "$out" && fail "a structural, text or gone line"
grep -q '; 1 new, 0 gone entries$' <<< "$out" || fail "the overall line does not count the new entry"

out=$("$compare" "$tmp/new" "$tmp/new" 2>&1); rc=$?
[ "$rc" -eq 0 ] || fail "same tree: exit $rc, expected 0"
grep -q '^study.json: 14 numbers, identical$' <<< "$out" || fail "same tree not identical: $out"

# The same row removed: one gone entry, which is not a difference.
cp "$tmp/new/study.json" "$tmp/old/study.json"
sed -i '/"spark"/d' "$tmp/new/study.json"
out=$("$compare" "$tmp/old" "$tmp/new" 2>&1); rc=$?
[ "$rc" -eq 0 ] || fail "a gone entry: exit $rc, expected 0 ($out)"
grep -q '^    gone: scenes.particle.methods\[label=spark\]$' <<< "$out" || fail "the gone entry not listed: $out"

# An array of numbers stays positional: one more h is a structural difference.
sed -i 's/"h": \[0.1, 0.05\]/"h": [0.1, 0.05, 0.025]/' "$tmp/new/study.json"
out=$("$compare" "$tmp/old" "$tmp/new" 2>&1); rc=$?
[ "$rc" -eq 1 ] || fail "a longer array of numbers: exit $rc, expected 1"
grep -q '^    structural: scenes.particle.h: array length 2 -> 3$' <<< "$out" || fail "not structural: $out"

# --ignore-key 'gc_*' (keys compare_results does not skip by itself): the keys it
# matches moved and are no difference; an exact name matches only itself; a number
# the pattern does not match still counts.
cat > "$tmp/old/study.json" << 'EOF2'
{"runs": [{"label": "rk4", "gc_first": 1.0, "gc_second": 2.0, "error": 1e-3}]}
EOF2
cat > "$tmp/new/study.json" << 'EOF2'
{"runs": [{"label": "rk4", "gc_first": 1.5, "gc_second": 2.5, "error": 1e-3}]}
EOF2
out=$("$compare" "$tmp/old" "$tmp/new" --tol 0 --ignore-key 'gc_*' 2>&1); rc=$?
[ "$rc" -eq 0 ] || fail "--ignore-key 'gc_*': exit $rc, expected 0 ($out)"
out=$("$compare" "$tmp/old" "$tmp/new" --tol 0 --ignore-key gc_first 2>&1); rc=$?
[ "$rc" -eq 1 ] || fail "--ignore-key gc_first: exit $rc, expected 1 (gc_second moved) ($out)"
sed -i 's/"error": 1e-3}/"error": 2e-3}/' "$tmp/new/study.json"
out=$("$compare" "$tmp/old" "$tmp/new" --tol 0 --ignore-key 'gc_*' 2>&1); rc=$?
[ "$rc" -eq 1 ] || fail "--ignore-key 'gc_*' with a changed error: exit $rc, expected 1 ($out)"

[ "$fails" -eq 0 ] && echo "ok"
exit $fails
