#!/usr/bin/env bash
# experiments/tools/check_fresh.sh in a throwaway git repository: a result made at
# the last commit that changed its code passes; one made before it, from a
# modified tree, at an unknown revision, or with uncommitted changes to its
# code is refused with exit 1 and one line naming `make sweep`.
set -uo pipefail
check=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" || exit 1
git init -q . && git config user.email t@t && git config user.name t
mkdir -p lib experiments results
echo a > lib/code.hpp && echo s > experiments/study_x.cpp && echo r > README.md
git add -A && git commit -qm one
rev1=$(git rev-parse HEAD)
result() { printf '{"meta": {"git_revision": "%s", "git_dirty": %s}}\n' "$1" "$2" > results/x.json; }
fails=0
expect() {  # expect RC DESCRIPTION
  local out rc
  out=$("$check" results/x.json experiments/study_x.cpp 2>&1)
  rc=$?
  if [ "$rc" -ne "$1" ]; then echo "FAIL: $2: exit $rc, expected $1 ($out)"; fails=1; return; fi
  if [ "$1" -ne 0 ] && { [ "$(printf '%s\n' "$out" | wc -l)" -ne 1 ] || ! grep -q "make sweep" <<< "$out"; }; then
    echo "FAIL: $2: not one line naming make sweep: $out"; fails=1; return
  fi
  echo "ok: $2${out:+: $out}"
}
result "$rev1" false; expect 0 "made at the last change"
echo r2 > README.md && git commit -qam "docs only"
expect 0 "a later commit that does not touch the code"
result "$rev1" true; expect 1 "made from a modified tree"
result 0123456789abcdef0123456789abcdef01234567 false; expect 1 "an unknown revision"
result "$rev1" false; echo b > lib/code.hpp; expect 1 "uncommitted change to the library"
git commit -qam "library change"; expect 1 "made before the last library change"
echo s2 > experiments/study_x.cpp && git commit -qam "study change"
result "$(git rev-parse HEAD~1)" false; expect 1 "made before the last change to its own source"
result "$(git rev-parse HEAD)" false; expect 0 "made at the current revision"
rm results/x.json; expect 1 "missing"
exit $fails
