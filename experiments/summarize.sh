#!/usr/bin/env bash
# Markdown tables of the study results (results/*.json -> stdout).  `make
# reproduce` writes them to results/summary.md; README.md quotes them.
set -euo pipefail
R=${1:-results}
# jq: a number to 3 significant digits (scientific when small or large), "-" for null.
G='def g: if . == null then "-" elif . == 0 then "0" else
  (fabs | log10 | floor) as $e |
  if $e >= -2 and $e < 4 then (. * pow(10; 2 - $e) | round / pow(10; 2 - $e) | tostring)
  else ((. / pow(10; $e) * 100 | round / 100 | tostring) + "e" + ($e | tostring)) end end;'

echo "## Convergence (results/convergence.json): fitted order, 4 finest h above 1e-10"
echo
# One column per scene in the file (every registered scene), one row per method.
jq -r "$G"'
  (.scenes | keys_unsorted) as $sc |
  "| method | \($sc | join(" | ")) |", "|---|\($sc | map("---|") | join(""))",
  ([.scenes[$sc[]].methods] | transpose[] |
   "| \(.[0].label) | \(map(.fitted_order | g) | join(" | ")) |")' "$R/convergence.json"
echo

echo "## Long horizon (results/long_horizon.json): h = 0.2, T = 2e5"
echo
echo "| scene | method | max \\|E-E0\\| | drift rate (per unit t) | envelope exponent | max \\|constraint\\| | fate | CPU s |"
echo "|---|---|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] |
  "| \($s) | \(.label) | \(.summary.max_abs_energy_error | g) | \(.summary.drift_rate | g) | \(.summary.envelope_growth_exponent | g) | \(.summary.max_abs_constraint | g) | \(.fate | gsub("[|]"; "\\|")) | \(.cpu_seconds | g) |"' "$R/long_horizon.json"
echo

echo "## Stability (results/stability.json): T = 200, h = 0.01 ... 10"
echo
echo "| scene | method | largest stable h (\\|E-E0\\| <= \\|E0\\|) | first failure (kind, t) | largest surviving h (solves converge, finite) |"
echo "|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] |
  "| \($s) | \(.label) | \(if .largest_stable_h then (.largest_stable_h | g) else "none" end) | \(if .first_failure then "h = \(.first_failure.h | g): \(.first_failure.failure.kind) at t = \(.first_failure.failure.time | g)" else "-" end) | \(if .largest_surviving_h then (.largest_surviving_h | g) else "none" end) |"' "$R/stability.json"
echo

echo "## Step costs (results/step_costs.json), CPU ns per step (CVODE: ms per run to T = 200)"
echo
echo "| benchmark | CPU |"
echo "|---|---|"
jq -r '.benchmarks[] | "| \(.name) | \(.cpu_ns | round) |"' "$R/step_costs.json"
echo
jq -r "$G"'"Particle DLA step / analytic Newton floor: \(.particle_dla_over_floor | g) (target <= \(.target_ratio))"' "$R/step_costs.json"
