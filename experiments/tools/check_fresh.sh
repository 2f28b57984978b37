#!/usr/bin/env bash
# check_fresh.sh RESULT.json SOURCE...
# Refuses (exit 1, one line) a committed result that make reproduce does not
# regenerate (the sweep's large tables, `make sweep`) when it was made from a
# modified tree, or at a revision before the last commit that changed the
# code it depends on: the library, the build, the scenes, the studies' shared
# headers and its own SOURCEs.  Uncommitted changes to that code also make it
# stale.  Outside a git checkout it cannot tell and says so.
set -euo pipefail
res=$1
shift
deps=(lib CMakeLists.txt cmake experiments/scenes experiments/studies/study.hpp experiments/studies/cluster.hpp
      experiments/studies/cluster.cpp experiments/studies/horizon.hpp experiments/studies/hand_steps.hpp "$@")
name=${res##*/}
if [ ! -f "$res" ]; then
  echo "$res is missing: run make sweep" >&2
  exit 1
fi
if ! git rev-parse --git-dir > /dev/null 2>&1; then
  echo "check_fresh: not a git checkout, $name not checked against the code" >&2
  exit 0
fi
rev=$(jq -r '.meta.git_revision // "unknown"' "$res")
dirty=$(jq -r 'if .meta.git_dirty == false then "false" else "true" end' "$res")
if [ "$dirty" != false ] || [ "$rev" = unknown ]; then
  echo "$name was made from a modified or unknown tree ($rev): run make sweep" >&2
  exit 1
fi
if ! git cat-file -e "$rev^{commit}" 2> /dev/null; then
  echo "$name was made at $rev, which this clone does not have (shallow?): run make sweep" >&2
  exit 1
fi
last=$(git log -1 --format=%H -- "${deps[@]}")
if ! git merge-base --is-ancestor "$last" "$rev"; then
  echo "$name was made at ${rev:0:12}, before ${last:0:12} changed the code it depends on: run make sweep" >&2
  exit 1
fi
if [ -n "$(git status --porcelain --untracked-files=no -- "${deps[@]}")" ]; then
  echo "$name predates uncommitted changes to the code it depends on: run make sweep" >&2
  exit 1
fi
