#!/bin/sh
# The fate-map sweep's wall time with each rank count given, one thread per
# rank, under mpirun; checks that every run's JSON equals the first's (meta and
# stats aside) and writes {ranks, wall_seconds, busy_seconds, identical, cores}.
#   experiments/tools/sweep_scaling.sh BINARY "MPIRUN" OUT.json RANKS...
# (Debian: GNU date and coreutils' nproc.)
set -eu
if [ $# -lt 4 ]; then
  echo "usage: $0 BINARY \"MPIRUN\" OUT.json RANKS..." >&2
  exit 2
fi
bin=$1 mpirun=$2 out=$3
shift 3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
trap 'exit 130' INT TERM
rows=""
first=""
mismatch=0
for n in "$@"; do
  start=$(date +%s.%N)
  if ! $mpirun --oversubscribe -np "$n" "$bin" --threads 1 -o "$tmp/r$n.json" 2> "$tmp/err$n"; then
    tr '\r' '\n' < "$tmp/err$n" | tail -20 >&2
    echo "sweep-scaling: the run with $n ranks failed" >&2
    exit 1
  fi
  end=$(date +%s.%N)
  wall=$(awk "BEGIN { print $end - $start }")
  jq -S 'del(.meta, .stats)' "$tmp/r$n.json" > "$tmp/s$n.json"
  if [ -z "$first" ]; then first=$n; fi
  if cmp -s "$tmp/s$first.json" "$tmp/s$n.json"; then same=true; else same=false; fi
  row=$(jq -c --argjson n "$n" --argjson wall "$wall" --argjson same "$same" \
    '{ranks: $n, wall_seconds: $wall, busy_seconds: .stats.busy_seconds, estimated_cost: .stats.estimated_cost,
      identical_to_first: $same}' "$tmp/r$n.json")
  rows="$rows${rows:+,}$row"
  echo "sweep-scaling: $n ranks: $wall s, identical: $same" >&2
  if [ "$same" = false ]; then mismatch=1; fi
done
size=$(jq -c '.size' "$tmp/r$first.json")
echo "{\"study\": \"fate_map_scaling\", \"cores\": $(nproc), \"size\": $size, \"runs\": [$rows]}" | jq . > "$out.tmp"
mv "$out.tmp" "$out"
if [ "$mismatch" = 1 ]; then echo "sweep-scaling: results differ between rank counts" >&2; exit 1; fi
