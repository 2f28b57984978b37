#!/usr/bin/env bash
# Markdown tables of the study results (results/*.json -> stdout).  `make
# reproduce` writes them to results/summary.md; experiments/tools/readme_tables.sh
# copies the sections README.md shows between its BEGIN/END markers.
#
#   experiments/tools/summarize.sh [RESULTS_DIR [NHI]]
#
# NHI (default build/bin/nhi): the runner, whose `nhi list --json` gives the
# scene classes of the decision table.
set -euo pipefail
R=${1:-results}
NHI=${2:-build/bin/nhi}
[ -x "$NHI" ] || { echo "summarize.sh: no runner $NHI (build it: make build; or pass its path)" >&2; exit 2; }
# jq: a number to 3 significant digits (scientific when small or large), "-" for
# null; the exponent is taken after rounding, so 0.009999 prints 0.01, not 10e-3.
G='def g: if . == null then "-" elif . == 0 then "0" else
  (fabs | log10 | floor) as $e0 |
  ((. / pow(10; $e0) * 100 | round / 100) | fabs) as $m |
  (if $m >= 10 then $e0 + 1 else $e0 end) as $e |
  if $e >= -2 and $e < 4 then (. * pow(10; 2 - $e) | round / pow(10; 2 - $e) | tostring)
  else ((. / pow(10; $e) * 100 | round / 100 | tostring) + "e" + ($e | tostring)) end end;'
# The classical Runge-Kutta methods of the work-precision study.
CLASSICAL='def classical: . == "rk4" or . == "rkf78" or . == "dopri5";'

# ---- The paper's scenes at the paper's step: Figures 1-4 and 1b-4b ----------
runs=()
for s in particle_fig12 robot_fig34; do
  for m in dla mp06 mp06tj rk4 benchmark; do
    [ -f "$R/${s}_$m.json" ] && runs+=("$R/${s}_$m.json")
  done
done
if [ ${#runs[@]} -gt 0 ]; then
echo "## Paper scenes at h = 0.2 (results/particle_fig12_*.json, results/robot_fig34_*.json): Figures 1-4 and 1b-4b"
echo
echo "max |E - E0| over t <= 100 and t <= 1000 (the recorded points, every second step) and over the whole run (every step, T = 4000); max |omega(q)v| with the runner's velocity (the DLA's: the central difference); the discrete constraint the method holds (the DLA's omega_d, mp06's omega(q)v)."
echo
echo "| scene | method | E0 | max \\|E-E0\\|, t <= 100 | t <= 1000 | whole run | max \\|omega(q)v\\| | max \\|discrete constraint\\| |"
echo "|---|---|---|---|---|---|---|---|"
jq -r "$G"'
  (.scene.system) as $s |
  (if .scene.method == "dla" then (if .scene.discretization == "symmetric" then "dla-sym" else "dla" end) + " a=\(.scene.alpha)"
   elif .scene.method == "benchmark" then "reference" else .scene.method end
   + (if (.scene.composition // "none") != "none" then "+" + .scene.composition else "" end)) as $lab |
  .energy[0] as $e0 |
  ([.t, .energy] | transpose) as $p |
  def window($T): [$p[] | select(.[0] <= $T) | .[1] - $e0 | fabs] | max;
  "| \($s) | \($lab) | \($e0 | g) | \(window(100) | g) | \(window(1000) | g) | \(.summary.max_abs_energy_error | g) | \(.summary.max_abs_constraint | g) | \(if .discrete_constraint then ([.discrete_constraint[][] | fabs] | max | g) else "-" end) |"' "${runs[@]}"
echo
fi

echo "## Convergence (results/convergence.json): fitted order, 4 finest h above the floor (1e-10, or 3 x the reference's own error where larger; \"-\": fewer than 3 points above it, or not studied)"
echo
# One column per scene in the file (every registered scene), one row per method,
# matched by label ("-" where a scene does not study the method: the group methods).
jq -r "$G"'
  (.scenes | keys_unsorted) as $sc |
  ([.scenes[].methods[].label] | reduce .[] as $l ([]; if any(.[]; . == $l) then . else . + [$l] end)) as $labels |
  "| method | \($sc | join(" | ")) |", "|---|\($sc | map("---|") | join(""))",
  ($labels[] as $l | . as $root |
   "| \($l) | \([$sc[] | . as $s | $root.scenes[$s].methods | map(select(.label == $l)) |
                  if length > 0 then (.[0].fitted_order | g) else "-" end] | join(" | ")) |")' "$R/convergence.json"
echo

if jq -e '[.scenes[].methods[] | select(.limit_speed_error != null)] | length > 0' "$R/convergence.json" > /dev/null; then
echo "### The limit motion (convergence study, scenes with a closed-form limit: the sleigh)"
echo
echo "Each method run from the scene's state to the settle time of the closed form (Sleigh::limit_motion: the turn rate below 2e-13 of its peak); error in the forward speed against c = sqrt(2E/m) and in the heading against theta_inf, at h = 0.2, 0.05 and 0.0125, and the fitted orders (as for q above)."
echo
echo "| scene | method | speed error, h = 0.2 | 0.05 | 0.0125 | order | heading error, h = 0.2 | 0.05 | 0.0125 | order |"
echo "|---|---|---|---|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] | select(.limit_speed_error != null) |
  "| \($s) | \(.label) | \(.limit_speed_error[0] | g) | \(.limit_speed_error[2] | g) | \(.limit_speed_error[4] | g) | \(.limit_speed_error_order | g) | \(.limit_heading_error[0] | g) | \(.limit_heading_error[2] | g) | \(.limit_heading_error[4] | g) | \(.limit_heading_error_order | g) |"' "$R/convergence.json"
echo
fi

echo "## Long horizon (results/long_horizon.json): 10^6 steps of the scene's h (0.2 on the paper's scenes: T = 2e5); the reference solution $(jq -r '.config.reference_steps // 1000000 | "\(.) steps"' "$R/long_horizon.json")"
echo
echo "The fate is read from the last decade [T/10, T] (lib/nhi/readings/fate.hpp; levels in the result's config): max |E-E0| at T/10^4 and at T, relative to |E0|; the running max's log-log slope over the last decade; the block means' rise over it."
echo
echo "| scene | method | max \\|E-E0\\| at T/1e4 | at T | / \\|E0\\| | last-decade slope | block-mean rise | max \\|constraint\\| | fate | CPU s |"
echo "|---|---|---|---|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] |
  "| \($s) | \(.label) | \(.tail.max_early | g) | \(.summary.max_abs_energy_error | g) | \(.tail.relative | g) | \(.tail.max_slope | g) | \(.tail.block_rise | g) | \(.summary.max_abs_constraint | g) | \(.fate | gsub("[|]"; "\\|")) | \(.cpu_seconds | g) |"' "$R/long_horizon.json"
echo

echo "### Long horizon: the other first integrals (contact oscillators: H_y = (y^2 + yd^2)/2, R = H - H_y)"
echo
echo "Offset or drift, read like the energy's fate from the last decade of the running max error (fate.hpp, read_integral)."
echo
echo "| scene | method | H_y | R | R - R0 at the end | fate of E |"
echo "|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.methods[] | select(.first_integrals != null) |
  "| \($s) | \(.label) | \(.first_integrals.H_y.reading.words) | \(.first_integrals.R.reading.words) | \(.first_integrals.R.final_error | g) | \(.fate | gsub("[|]"; "\\|")) |"' "$R/long_horizon.json"
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
echo "### Stability and the solver's start: the implicit methods"
echo
jq -r '"Largest stable h of each implicit method with its own start (the predictor) and with every step started from the root continued from h -> 0 (checked at h >= \(.config.roots.h_from); \"< \(.config.roots.h_from)\": at no checked h), and the largest h up to which the runs with the predictor took the continued root at every step. Where the two limits differ, the limit with the predictor is partly that of its solver."' "$R/stability.json"
echo
echo "| scene | method | largest stable h, own start | from the continued root | own start followed the continued root up to |"
echo "|---|---|---|---|---|"
jq -r "$G"'.config.roots.h_from as $from | .scenes | to_entries[] | .key as $s | .value.methods[] | select(.roots) |
  "| \($s) | \(.label) | \(if .largest_stable_h then (.largest_stable_h | g) else "none" end) | \(if .roots.largest_stable_h_continued then (.roots.largest_stable_h_continued | g) else "< \($from | g)" end) | \(if .roots.followed_continued_root_up_to then (.roots.followed_continued_root_up_to | g) else "< \($from | g)" end) |"' "$R/stability.json"
echo

echo "## Step costs (results/step_costs.json), CPU ns per step (CVODE: ms per run to T = 200)"
echo
echo "| benchmark | CPU | / RK4 (same scene, same run) | Newton iterations per step |"
echo "|---|---|---|---|"
jq -r "$G"'.benchmarks | sort_by(.name)[] | "| \(.name) | \(.cpu_ns | round) | \(if .ratio_to_rk4 then (.ratio_to_rk4 * 100 | round / 100 | tostring) else "-" end) | \(if .counters.newton_iterations_per_step then (.counters.newton_iterations_per_step * 100 | round / 100 | tostring) else "-" end) |"' "$R/step_costs.json"
echo
jq -r "$G"'"Particle DLA step / analytic Newton floor: \(.particle_dla_over_floor | g) (target <= \(.target_ratio))"' "$R/step_costs.json"
echo
jq -r "$G"'if .nr_mp06_over_floor then "contact_oscillator_nr mp06 step / hand-reduced floor (the step by hand as one scalar equation, experiments/studies/hand_steps.hpp): \(.nr_mp06_over_floor | g)" else empty end' "$R/step_costs.json"
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

echo "## Step cost ratios (results/step_costs.json): CPU per step / RK4's on the same scene in the same run, h = 0.2"
echo
echo "The methods of the work-precision study, steps from each scene's default state (bench_steps); the CPU times are in results/step_costs.json."
echo
jq -r "$G"'
  ([.benchmarks[] | select(.name | test("/")) | {scene: (.name | split("/")[0]), method: (.name | split("/")[1]), r: .ratio_to_rk4}]) as $rows |
  ($rows | map(.scene) | unique) as $scenes |
  ($main | map(gsub(" "; "_")) | map(select(. as $m | $rows | any(.method == $m)))) as $methods |
  "| method | " + ($scenes | join(" | ")) + " |",
  "|---|" + ($scenes | map("---|") | join("")),
  ($methods[] as $m | "| \($m) | " + ([$scenes[] as $s | [$rows[] | select(.scene == $s and .method == $m)][0] |
     if . == null or .r == null then "-" else (.r | g) end] | join(" | ")) + " |")' \
  --argjson main "$(jq -c '[.scenes[].runs[].label] | unique' "$R/work_precision.json")" "$R/step_costs.json"
echo
jq -r "$G"'"The particle'"'"'s DLA map (alpha = 1/2) costs \(.particle_dla_over_floor | g) times a hand-derived Newton step with the analytic Jacobian (target <= \(.target_ratio))" +
  (if .nr_mp06_over_floor then "; mp06 on contact_oscillator_nr \(.nr_mp06_over_floor | g) times the step reduced by hand to one scalar equation (experiments/studies/hand_steps.hpp)." else "." end)' "$R/step_costs.json"
echo
jq -r "$G"'[.scenes[] | [.runs[] | select((.label == "reference" or .label == "rkf78") and .param == 1e-12 and .cpu_final != null)]
  | select(length == 2) | (map(select(.label == "reference"))[0].cpu_final / map(select(.label == "rkf78"))[0].cpu_final)] |
  if length > 0 then "CVODE (the reference solution) at tolerance 1e-12 takes \(min | g) to \(max | g) times the CPU time of rkf78 at 1e-12 to T = 10 (results/work_precision.json)." else empty end' "$R/work_precision.json"
echo

echo "## Step-cost targets (results/step_costs.json): h = 0.2, a step's CPU time against RK4's on the same scene"
echo
echo "| target | measured | met |"
echo "|---|---|---|"
jq -r "$G"'
  (.benchmarks | map({key: .name, value: .}) | from_entries) as $b |
  def cell($scene; $method; f): $b["\($scene)/\($method)"] | if . == null then null else f end;
  def row($what; $method; $scenes; $limit; f):
    [$scenes[] as $s | {s: $s, v: cell($s; $method; f)} | select(.v != null)] as $c |
    if ($c | length) == 0 then empty else
    "| \($what) | \($c | map("\(.s) \(.v | g)") | join(", ")) | \(if all($c[]; .v <= $limit) then "yes" elif any($c[]; .v <= $limit) then "on " + ([$c[] | select(.v <= $limit) | .s] | join(", ")) else "no" end) |" end;
  row("midpoint DLA (alpha = 1/2) <= 3x RK4"; "dla_a=0.5"; ["particle", "robot"]; 3; .ratio_to_rk4),
  row("symmetric DLA (alpha = 0) <= 3x RK4"; "dla-sym_a=0"; ["particle", "robot"]; 3; .ratio_to_rk4),
  row("midpoint DLA <= 1.5 Newton iterations per step"; "dla_a=0.5"; ["particle", "robot"]; 1.5; .counters.newton_iterations_per_step),
  row("mp06 <= 1x RK4"; "mp06"; ["particle", "robot"]; 1; .ratio_to_rk4),
  row("mp06 <= 1.5x RK4"; "mp06"; ["contact_oscillator", "chaotic_oscillator", "sleigh", "contact_oscillator_nr"]; 1.5; .ratio_to_rk4),
  row("discrete gradient <= 3x RK4"; "discrete_gradient"; ["particle", "robot", "contact_oscillator", "chaotic_oscillator", "sleigh", "contact_oscillator_nr"]; 3; .ratio_to_rk4),
  "| particle DLA map <= \(.target_ratio)x the analytic Newton step | \(.particle_dla_over_floor | g) | \(if .particle_dla_over_floor <= .target_ratio then "yes" else "no" end) |"' "$R/step_costs.json"
echo
# ---- Which method when (results/work_precision.json) --------------------------
# Per scene, horizon T and energy-error target: each method's least CPU time to
# keep max |E - E0| over [0, T] below the target (both tables below).
WP='
def extrap: .max_energy_error * ([1, .max_energy_error / ([.max_energy_error_short, 1e-300] | max)] | max);
def horizon($h; $measured):
  if $h == "1e2" then {err: .max_energy_error_short, cpu: .cpu_energy_short, range: .cpu_energy_short_range}
  elif $h == "1e4" then {err: .max_energy_error, cpu: .cpu_energy, range: .cpu_energy_range}
  elif $measured then {err: .max_energy_error_long, cpu: .cpu_energy_long, range: .cpu_energy_long_range}
  else {err: extrap, cpu: (.cpu_energy * 100), range: (.cpu_energy_range | map(. * 100))} end;
# Two entries of best() tie when their CPU ranges (min, max of the timings) overlap.
def tie($a; $b): $b.range[0] <= $a.range[1];
# The scene keys of an entry without its h or tolerance.
def method_keys: .keys | sub(" (h|tolerance)=[^ ]*$"; "");
def measured_long: [.runs[] | select(.status == "ok" and .max_energy_error_long != null)] | length > 0;
# input: one scene of work_precision.json; output: [{label, param, err, cpu}], one per
# method that keeps the error below $tol over $h, fastest first.
def best($h; $tol):
  measured_long as $measured |
  [.runs[] | select(.status == "ok") | select($h != "1e6" or ($measured | not) or .max_energy_error_long != null)
   | {label: .label, param: .param, keys: .keys} + horizon($h; $measured) | select(.err != null and .err <= $tol)]
  | group_by(.label) | map(min_by(.cpu)) | sort_by(.cpu);
def horizons: "1e2", "1e4", "1e6";
def targets: 1e-2, 1e-4, 1e-6, 1e-8;
def paper_dla: startswith("dla");
'
# Scene classes of the decision table (Modin & Verdier's: reversible or not,
# integrable or not): each system's "class" in `nhi list --json`, which follows
# from the traits it declares (lib/nhi/roles/system.hpp), its scenes in the registry's
# order.  The classes come in this order, any other after them; a scene the
# runner does not know is a class of its own.
CLASS_ORDER='["reversible, integrable", "reversible, chaotic", "reversible flow, non-reversible maps",
              "not reversible", "reversible, attracted to a line", "rigid body"]'
CLASSES=$("$NHI" list --json | jq -c --argjson order "$CLASS_ORDER" '
  [.systems[] | {class, scene: .name}] as $sys |
  reduce ($order[], $sys[].class) as $c ([]; if index($c) then . else . + [$c] end) |
  map(. as $c | {name: $c, scenes: [$sys[] | select(.class == $c) | .scene]}) | map(select(.scenes | length > 0))')
# input: work_precision.json; $classes as above.
CLS='
def geomean: map(log) | add / length | exp;
def classes: (.scenes | keys_unsorted) as $all |
  ($classes | map(.scenes |= map(select(. as $s | $all | index($s))) | select(.scenes | length > 0))) as $cl |
  $cl + [$all[] | select(. as $s | $cl | all(.scenes | index($s) | not)) | {name: ., scenes: [.]}];
# One row per class, horizon and pair of targets: the methods that reach every
# target on every scene of the class, ranked by the geometric mean over those
# cells of their CPU time over the cell'"'"'s fastest.
def class_rows: .scenes as $S | classes[] |
  .name as $c | .scenes as $cs |
  horizons as $h | ([1e-2, 1e-4], [1e-6, 1e-8]) as $band |
  [$cs[] as $s | $band[] as $t |
   {scene: $s, extrap: ($h == "1e6" and ($S[$s] | measured_long | not)),
    best: ($S[$s] | best($h; $t) | map({key: .label, value: .}) | from_entries)}] as $cells |
  [$cells[].best | [.[].cpu] | min] as $fastest |
  ([$cells[].best | keys] | reduce .[1:][] as $k (.[0]; . - (. - $k))) as $common |
  {class: $c, h: $h, band: $band, n: ($cells | length),
   extrap: ([$cells[] | select(.extrap) | .scene] | unique),
   measured: ([$cells[] | select(.extrap | not) | .scene] | unique),
   rank: ([$common[] as $m |
     {label: $m,
      keys: ($cells[0].best[$m] | method_keys),
      score: ([range(0; $cells | length) as $i | $cells[$i].best[$m].cpu / $fastest[$i]] | geomean),
      score_range: [([range(0; $cells | length) as $i | $cells[$i].best[$m].range[0] / $fastest[$i]] | geomean),
                    ([range(0; $cells | length) as $i | $cells[$i].best[$m].range[1] / $fastest[$i]] | geomean)],
      wins: ([range(0; $cells | length) as $i | select($cells[$i].best[$m].cpu == $fastest[$i])] | length),
      params: [$cells[].best[$m].param]}] | sort_by(.score))};
'

echo "## Which method when, by scene class (results/work_precision.json)"
echo
# The DLA family's places in both tables, so that this sentence is the data's.
jq -r "$G$WP$CLS"'
  ([.scenes[].runs[].label | select(paper_dla)] | unique) as $dla |
  [.scenes[] | horizons as $h | targets as $t | best($h; $t)[0:2][] | .label | select(paper_dla)] as $top |
  [class_rows | .rank[0:2][] | .label | select(paper_dla)] as $ctop |
  if ($top + $ctop | length) == 0 then
    "The paper'"'"'s DLA and its variants (\($dla | join(", "))) are neither first nor second in any row of this table or of the per-scene table (results/summary.md, \"Which method when\")."
  else
    "The paper'"'"'s DLA and its variants are first or second in \($ctop | length) rows of this table and \($top | length) of the per-scene table (results/summary.md, \"Which method when\"): \($top + $ctop | unique | join(", "))."
  end' --argjson classes "$CLASSES" "$R/work_precision.json"
echo
echo "One row per scene class, horizon T and pair of energy-error targets: the method with the least CPU time to keep max |E - E0| over [0, T] below the target, scored over the class's scenes and both targets (geometric mean of its CPU time over the fastest method's in each cell; a method counts only if it reaches every target on every scene of the class). \"Fastest in\": the cells where it is the fastest; its h or tolerance in parentheses; \"x\": how much slower (the same score) the runner-up and the best classical Runge-Kutta method (rk4, rkf78, dopri5) are. T = 1e6 is extrapolated where marked, as in the per-scene table of results/summary.md."
echo
echo -n "Classes: "
jq -r "$CLS"'classes | map("\(.name) (\(.scenes | join(", ")))") | join("; ") + "."' \
  --argjson classes "$CLASSES" "$R/work_precision.json"
echo
echo "| scene class | T | targets | method: scene keys, h or tolerance | fastest in | runner-up | x | best classical | x |"
echo "|---|---|---|---|---|---|---|---|---|"
jq -r "$G$WP$CLASSICAL$CLS"'
  def span: unique | if length > 1 then "\(first | g) to \(last | g)" else (.[0] | g) end;
  class_rows | .rank as $rank |
  ([$rank[] | select(.label | classical)][0]) as $rk |
  (if (.extrap | length) == 0 then "" elif (.measured | length) == 0 then " (extrap.)"
   else " (extrap. but \(.measured | join(", ")))" end) as $tag |
  "| \(.class) | \(.h)\($tag) | \(.band | map(g) | join(", ")) | " +
  (if ($rank | length) == 0 then "none reaches every target | - | - | - | - | -"
   else $rank[0] as $b |
     "\($b.label): `\($b.keys)` \(if ($b.keys | test("benchmark|rkf78|dopri5")) then "tolerance" else "h" end) \($b.params | span) | \($b.wins) of \(.n) | " +
     (if ($rank | length) > 1 then "\($rank[1].label)\(if $rank[1].score_range[0] <= $b.score_range[1] then " (tie)" else "" end) | \($rank[1].score / $b.score | g)" else "- | -" end) + " | " +
     (if $rk == null then "none | -" else "\($rk.label) | \($rk.score / $b.score | g)" end) end) + " |"' \
  --argjson classes "$CLASSES" "$R/work_precision.json"
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
echo "| scene | T | target | fastest: scene keys | CPU s | runner-up | x slower | best classical | x slower |"
echo "|---|---|---|---|---|---|---|---|---|"
jq -r "$G$WP$CLASSICAL"'
  .scenes | to_entries[] | .key as $s | .value as $scene |
  ($scene | measured_long) as $measured |
  horizons as $h | targets as $tol |
  (if $h == "1e6" and ($measured | not) then " (extrap.)" else "" end) as $tag |
  ($scene | best($h; $tol)) as $best |
  ([$best[] | select(.label | classical)][0]) as $rk |
  if ($best | length) == 0 then "| \($s) | \($h)\($tag) | \($tol | g) | none reaches it | - | - | - | - | - |"
  else "| \($s) | \($h)\($tag) | \($tol | g) | \($best[0].label): `\($best[0].keys)` | \($best[0].cpu | g) | \(if ($best | length) > 1 then $best[1].label + (if tie($best[0]; $best[1]) then " (tie)" else "" end) else "-" end) | \(if ($best | length) > 1 then ($best[1].cpu / $best[0].cpu | g) else "-" end) | \(if $rk then $rk.label else "none" end) | \(if $rk then ($rk.cpu / $best[0].cpu | g) else "-" end) |" end' "$R/work_precision.json"

# ---- SPARK against mp06's compositions (study_work_precision) ------------
echo "## SPARK against mp06's compositions at equal error (results/work_precision.json)"
echo
echo "CPU time to bring max |q(T) - q_ref(T)| at T = 10 below the target, SPARK over mp06's composition of the same order (order 4: spark s=3 over mp06+triple_jump; order 6: spark s=4 over mp06+order6), each at its cheapest h; - where one of the two reaches no target on the h grid."
echo
echo "| scene | order 4, 1e-6 | order 6, 1e-6 | order 6, 1e-9 |"
echo "|---|---|---|---|"
jq -r '
def best($r; $l; $t): [$r[] | select(.label == $l and .status == "ok" and .final_error <= $t) | .cpu_final] | min;
def ratio($a; $b): if $a == null or $b == null then "-" else ($a / $b * 10 | round / 10 | tostring) end;
.scenes | to_entries[] | .value.runs as $r |
  "| \(.key) | \(ratio(best($r; "spark s=3"; 1e-6); best($r; "mp06+triple_jump"; 1e-6))) | \(ratio(best($r; "spark s=4"; 1e-6); best($r; "mp06+order6"; 1e-6))) | \(ratio(best($r; "spark s=4"; 1e-9); best($r; "mp06+order6"; 1e-9))) |"' "$R/work_precision.json"
echo

# ---- Growth of the global error (study_global_error) ------------------------
if [ -f "$R/global_error.json" ]; then
echo "## Growth of the global error (results/global_error.json)"
echo
jq -r '"\(.config.steps) steps of h = \(.config.h) on each scene that declares itself integrable; error max_i |q_i(t) - q_ref,i(t)| against the exact solution where there is one, else CVODE at 1e-13; growth exponent: the log-log slope of the error over [T/100, T] where it is between \(.config.floor) and \(.config.saturation) (1: linear growth, 2: quadratic; - where fewer than 3 checkpoints qualify; a fit over few points, the error near its floor or already O(1), says little)."' "$R/global_error.json"
echo
echo "| method | $(jq -r '[.scenes | keys_unsorted[]] | join(" | ")' "$R/global_error.json") |"
echo "|---|$(jq -r '[.scenes | keys_unsorted[] | "---"] | join("|")' "$R/global_error.json")|"
# Rows by label (a method studied on some scenes only, as dla-group on the
# rigid bodies, has "-" elsewhere).
jq -r "$G"'. as $root | ($root.scenes | keys_unsorted) as $sc |
  ([$root.scenes[$sc[]].methods[].label] | reduce .[] as $l ([]; if index($l) then . else . + [$l] end))[] as $l |
  "| \($l) | " + ([$sc[] | . as $s | ([$root.scenes[$s].methods[] | select(.label == $l)][0]) |
    if . == null then "-" elif .status != "ok" then "failed" else "t^\(.growth_exponent | g) (\(.fit_points) points; \(.error[-1] | g) at T)" end] | join(" | ")) + " |"' "$R/global_error.json"
echo
fi

# ---- Drift counted over initial states (study_states) ----------------------
if [ -f "$R/states.json" ]; then
echo "## Drift over initial states (results/states.json)"
echo
jq -r '"\(.config.states) initial states (the scene'"'"'s section family: H = 3/2, H_y = 1/2, zd0 = 0, z0 spread over +-0.9 sqrt 2), \(.config.steps) steps of h each; \"drifting\": the run failed or its last decade grows above round-off (lib/nhi/readings/fate.hpp; an error below \(.config.fate_levels.roundoff_relative) |E0| that grows is round-off adding up). Slope: the running max of |E - E0| over the last decade, median [min, max] over the states; error at T: |E(T) - E0| / |E0|, median (max)."' "$R/states.json"
echo
echo "| scene | epsilon | h | method | drifting | last-decade slope | error at T |"
echo "|---|---|---|---|---|---|---|"
jq -r "$G"'.scenes | to_entries[] | .key as $s | .value.cases[] | . as $c | .methods[] |
  "| \($s) | \($c.epsilon) | \($c.h | g) | \(.label) | \(.drifting) of \(.runs | length)\(if .failed > 0 then " (\(.failed) failed)" else "" end)\(if .at_roundoff > 0 then " (\(.at_roundoff) growing at round-off)" else "" end) | \(.median_slope | g) [\(.min_slope | g), \(.max_slope | g)] | \(.median_relative_error_at_T | g) (\(.max_relative_error_at_T | g)) |"' "$R/states.json"
echo
echo "### Drift over initial states, by method: states drifting of 10 at (epsilon, h) = $(jq -r '[.scenes | to_entries[0].value.cases[] | "(\(.epsilon), \(.h * 1000 | round / 1000))"] | join(", ")' "$R/states.json")"
echo
echo "| method | $(jq -r '[.scenes | keys_unsorted[]] | join(" | ")' "$R/states.json") |"
echo "|---|$(jq -r '[.scenes | keys_unsorted[] | "---"] | join("|")' "$R/states.json")|"
jq -r '(.scenes | keys_unsorted) as $sc | [.scenes[$sc[]] | [.cases[].methods] | transpose] | transpose[] |
  "| \(.[0][0].label) | " + (map(map(.drifting | tostring) | join(", ")) | join(" | ")) + " |"' "$R/states.json"
echo
fi

# ---- Symmetry and reversibility of the one-step maps (study_geometry) -------
if [ -f "$R/geometry.json" ] && jq -e '.reversibility' "$R/geometry.json" > /dev/null; then
echo "## Symmetry and reversibility of the maps (results/geometry.json, \"reversibility\")"
echo
jq -r '"One step of each scene file'"'"'s h from \(.reversibility.scenes | to_entries[0].value.states) states on the constraint along an RK4 run; the largest relative defect: symmetry |Phi_-h Phi_h z - z|, reversibility under rho(q, v) = (q, -v) |rho Phi_h rho Phi_h z - z|, in q and in (q, v). The DLA is a map of (q, p mod omega^T): its defects are statements in q only."' "$R/geometry.json"
echo
echo "| scene | reversible scene | method | symmetric | symmetry, q | symmetry, (q, v) | reversibility, q | reversibility, (q, v) |"
echo "|---|---|---|---|---|---|---|---|"
jq -r "$G"'.reversibility.scenes | to_entries[] | .key as $s | .value as $v | $v.methods[] |
  "| \($s) | \(if $v.reversible then "yes" else "no" end) | \(.label) | \(if .symmetric then "yes" else "no" end) | \(.symmetry_defect_q | g) | \(.symmetry_defect_phase | g) | \(.reversibility_defect_q | g) | \(.reversibility_defect_phase | g) |"' "$R/geometry.json"
echo
fi

# ---- The fate-map sweep (make sweep; not part of make reproduce) --------------
if [ -f "$R/fate_map.json" ]; then
echo
echo "## Fate map (results/fate_map.json): largest h with every run stable"
echo
jq -r '"\(.size.runs) runs of T = \(.config.T), \(.config.states) initial states on one energy level, h from \(.config.h | min) to \(.config.h | max) (\(.config.h | length) values); per scene, \(.config.param) and method the largest grid h up to which every run is stable (|E - E0| <= |E0| to T, solves converged, finite)."' "$R/fate_map.json"
echo
jq -r "$G"'
  .config.values as $v |
  "| scene | method | " + ($v | map("\(.)") | map("epsilon = " + .) | join(" | ")) + " |",
  "|---|---|" + ($v | map("---|") | join("")),
  (.scenes | to_entries[] | .key as $s | .value.by_value as $bv |
   ($bv[0].methods | map(.label))[] as $l |
   "| \($s) | \($l) | " + ([$bv[] | .methods[] | select(.label == $l) | .largest_h_all_stable | g] | join(" | ")) + " |")' "$R/fate_map.json"
fi
if [ -f "$R/fate_map_roots.json" ]; then
echo
echo "## Fate map and the solver's start (results/fate_map_roots.json): stable runs out of $(jq .config.states "$R/fate_map_roots.json")"
echo
jq -r '"The implicit methods at h >= \(.config.h | min), \(.config.param) = \(.config.values | map(tostring) | join(", ")): per h, the stable runs with the method'"'"'s own start / from the root continued from h -> 0 / the runs whose own start left the continued root at some step."' "$R/fate_map_roots.json"
echo
jq -r "$G"'
  .config.h as $h |
  "| scene | value | method | " + ($h | map("h = \(. | g)") | join(" | ")) + " |",
  "|---|---|---|" + ($h | map("---|") | join("")),
  (.scenes | to_entries[] | .key as $s | .value.by_value[] | .value as $e | .methods[] |
   . as $m | "| \($s) | \($e) | \(.label) | " + ([range(0; $h | length)] | map("\($m.stable[.]) / \($m.stable_continued[.]) / \($m.other_root[.])") | join(" | ")) + " |")' "$R/fate_map_roots.json"
fi
if [ -f "$R/fate_map_scaling.json" ]; then
echo
echo "## Fate-map scaling (results/fate_map_scaling.json): the sweep with N ranks of one thread"
echo
jq -r "$G"'
  "The same sweep (\(.size.runs) runs) on \(.cores) cores; every run'"'"'s JSON equal to the first'"'"'s: \(all(.runs[]; .identical_to_first)).",
  "",
  "| ranks | wall s | busy s per rank | speed-up |",
  "|---|---|---|---|",
  (.runs[0].wall_seconds as $w1 | .runs[] |
   "| \(.ranks) | \(.wall_seconds | g) | \(.busy_seconds | map(g) | join(", ")) | \($w1 / .wall_seconds | g) |")' "$R/fate_map_scaling.json"
fi
