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

echo "## Long horizon (results/long_horizon.json): 10^6 steps of the scene's h (0.2 on the paper's scenes: T = 2e5); the reference solution $(jq -r '.config.reference_steps // 1000000 | "\(.) steps"' "$R/long_horizon.json")"
echo
echo "| scene | method | max \\|E-E0\\| | drift rate (per unit t) | envelope exponent | max \\|constraint\\| | fate | CPU s |"
echo "|---|---|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] |
  "| \($s) | \(.label) | \(.summary.max_abs_energy_error | g) | \(.summary.drift_rate | g) | \(.summary.envelope_growth_exponent | g) | \(.summary.max_abs_constraint | g) | \(.fate | gsub("[|]"; "\\|")) | \(.cpu_seconds | g) |"' "$R/long_horizon.json"
echo

echo "### Long horizon: the other first integrals (contact oscillators: H_y = (y^2 + yd^2)/2, R = H - H_y)"
echo
echo "| scene | method | max \\|H_y - H_y0\\| | max \\|R - R0\\| | R - R0 at the end | fate of E |"
echo "|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] | select(.first_integrals != null) |
  "| \($s) | \(.label) | \(.summary.max_abs_H_y_error | g) | \(.summary.max_abs_R_error | g) | \(.first_integrals.R.final_error | g) | \(.fate | gsub("[|]"; "\\|")) |"' "$R/long_horizon.json"
echo

if [ -f "$R/poincare.json" ]; then
echo "## Poincare sections (results/poincare.json): (z, zd) at each maximum of y, h = 2 sin(pi/40), 10 initial states, 24000 steps"
echo
echo "Thickness: median over 36 angular bins of the radial spread of a state's section points, as a ratio to the"
echo "reference solution's; median over the 10 states. max |y - 1|: the error of y's amplitude (y at the sections is"
echo "y's maximum); the first integrals are read at the grid point after each section."
echo
echo "| scene | method | thickness / reference | max \\|R - R0\\| at sections | max \\|H_y - H_y0\\| | max \\|y - 1\\| | all ok | CPU s |"
echo "|---|---|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] |
  "| \($s) | \(.label) | \(.summary.median_thickness_ratio | g) | \(.summary.max_abs_R_error | g) | \(.summary.max_abs_H_y_error | g) | \(.summary.max_abs_y_minus_y0 | g) | \(.summary.all_ok) | \(.summary.cpu_seconds | g) |"' "$R/poincare.json"
echo
fi

echo "## Stability (results/stability.json): T = 200, h = 0.01 ... 10"
echo
echo "| scene | method | largest stable h (\\|E-E0\\| <= \\|E0\\|) | first failure (kind, t) | largest surviving h (solves converge, finite) |"
echo "|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] |
  "| \($s) | \(.label) | \(if .largest_stable_h then (.largest_stable_h | g) else "none" end) | \(if .first_failure then "h = \(.first_failure.h | g): \(.first_failure.failure.kind) at t = \(.first_failure.failure.time | g)" else "-" end) | \(if .largest_surviving_h then (.largest_surviving_h | g) else "none" end) |"' "$R/stability.json"
echo

echo "## Step costs (results/step_costs.json), CPU ns per step (CVODE: ms per run to T = 200)"
echo
echo "| benchmark | CPU | / RK4 (same scene, same run) | Newton iterations per step |"
echo "|---|---|---|---|"
jq -r "$G"'.benchmarks | sort_by(.name)[] | "| \(.name) | \(.cpu_ns | round) | \(if .ratio_to_rk4 then (.ratio_to_rk4 * 100 | round / 100 | tostring) else "-" end) | \(if .counters.newton_iterations_per_step then (.counters.newton_iterations_per_step * 100 | round / 100 | tostring) else "-" end) |"' "$R/step_costs.json"
echo
jq -r "$G"'"Particle DLA step / analytic Newton floor: \(.particle_dla_over_floor | g) (target <= \(.target_ratio))"' "$R/step_costs.json"
echo
jq -r "$G"'if .nr_mp06_over_floor then "contact_oscillator_nr mp06 step / hand-reduced floor (the step by hand as one scalar equation, experiments/hand_steps.hpp): \(.nr_mp06_over_floor | g)" else empty end' "$R/step_costs.json"
echo
echo "The same run as one row per method: ns per step / ratio to that scene's RK4 step / Newton"
echo "iterations per step (implicit methods; a composition counts every stage's)."
echo
jq -r "$G"'
  [.benchmarks[] | select(.name | test("/") and (test("reference_run|analytic|dla_map|floor") | not))
   | {scene: (.name | split("/")[0]), method: (.name | split("/")[1]), ns: .cpu_ns, r: .ratio_to_rk4,
      it: .counters.newton_iterations_per_step}] as $rows |
  ($rows | map(.scene) | unique) as $scenes |
  ($rows | map(.method) | unique) as $methods |
  "| method | " + ($scenes | join(" | ")) + " |",
  "|---|" + ($scenes | map("---|") | join("")),
  ($methods[] as $m | "| \($m) | " + ([$scenes[] as $s | ($rows[] | select(.scene == $s and .method == $m)) //
     null | if . == null then "-" else "\(.ns | round) / \(if .r then (.r * 100 | round / 100 | tostring) else "?" end)\(if .it then " / \(.it * 100 | round / 100)" else "" end)" end] | join(" | ")) + " |")' "$R/step_costs.json"
echo

echo "## Which method when (results/work_precision.json): least CPU time to keep max |E - E0| below a target"
echo
echo "Per scene, horizon and target: the method (and its h or tolerance) that keeps the largest energy"
echo "error over [0, T] below the target at the least CPU time, the runner-up method, and the cheapest"
echo "classical Runge-Kutta (rk4, rkf78, dopri5). T = 1e2 and 1e4 are measured (the same runs:"
echo "max over the first 100 time units and over 1e4). T = 1e6 is measured on the scenes the study"
echo "runs that long (config.long_scenes; only the configurations it runs there compete) and"
echo "extrapolated on the others: error(1e6) = error(1e4) * max(1, error(1e4)/error(1e2)) (the"
echo "measured growth continued as a power law), CPU(1e6) = 100 CPU(1e4)."
echo
echo "| scene | T | target | fastest (h or tol) | CPU s | runner-up | x slower | best classical | x slower |"
echo "|---|---|---|---|---|---|---|---|---|"
jq -r "$G"'
  def extrap: .max_energy_error * ([1, .max_energy_error / ([.max_energy_error_short, 1e-300] | max)] | max);
  def horizon($h; $measured):
    if $h == "1e2" then {err: .max_energy_error_short, cpu: .cpu_energy_short}
    elif $h == "1e4" then {err: .max_energy_error, cpu: .cpu_energy}
    elif $measured then {err: .max_energy_error_long, cpu: .cpu_energy_long}
    else {err: extrap, cpu: (.cpu_energy * 100)} end;
  .scenes | to_entries[] | .key as $s |
  [.value.runs[] | select(.status == "ok")] as $runs |
  ([$runs[] | select(.max_energy_error_long != null)] | length > 0) as $measured |
  ("1e2", "1e4", "1e6") as $h | (1e-2, 1e-4, 1e-6, 1e-8) as $tol |
  (if $h == "1e6" and ($measured | not) then " (extrap.)" else "" end) as $tag |
  ([$runs[] | select($h != "1e6" or ($measured | not) or .max_energy_error_long != null)
   | {label: .label, param: .param} + horizon($h; $measured) | select(.err != null and .err <= $tol)]
   | group_by(.label) | map(min_by(.cpu)) | sort_by(.cpu)) as $best |
  ([$best[] | select(.label == "rk4" or .label == "rkf78" or .label == "dopri5")][0]) as $rk |
  if ($best | length) == 0 then "| \($s) | \($h)\($tag) | \($tol | g) | none reaches it | - | - | - | - | - |"
  else "| \($s) | \($h)\($tag) | \($tol | g) | \($best[0].label) (\($best[0].param | g)) | \($best[0].cpu | g) | \(if ($best | length) > 1 then $best[1].label else "-" end) | \(if ($best | length) > 1 then ($best[1].cpu / $best[0].cpu | g) else "-" end) | \(if $rk then $rk.label else "none" end) | \(if $rk then ($rk.cpu / $best[0].cpu | g) else "-" end) |" end' "$R/work_precision.json"
