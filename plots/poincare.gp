# Study 5: Poincare sections (z, zd) once per y period, one panel per method,
# one colour per initial state.
# Called as gnuplot -e "file='results/poincare.json'; scene='contact_oscillator'; out='plots/poincare_contact_oscillator.png'" plots/poincare.gp
load "plots/style.gp"
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   N methods, S initial states; TITLE[i + 1], the panel title of method i
#   (label, median thickness ratio, max |R - R_0|), STY[i + 1] its method_ls;
#   $P<i>_<j>: z, dz/dt of the section points of method i from initial state j,
#   points with a missing coordinate dropped.
load jq_script(sprintf("--arg scene '%s'", scene), \
  '.scenes[$scene] as $s | ($s.initial_states | length) as $S ' . \
  '| "N = \($s.methods | length)", "S = \($S)", "array TITLE[N]", "array STY[N]", ' . \
  '($s.methods | to_entries[] | .key as $i | .value ' . \
  ' | "STY[\($i + 1)] = method_ls(\(.label | gp))", "TITLE[\($i + 1)] = \("\(.label)\nthickness ×\(.summary.median_thickness_ratio // "-" | if type == "number" then (. * 100 | round / 100) else . end), max |R − R_0| \(.summary.max_abs_R_error | . * 1e4 | round / 1e4)" | gp)", ' . \
  '   (range($S) as $j | jq_block("$P\($i)_\($j)"; ' . \
  '      .runs[$j] | [.z, .zd] | transpose[] | select(.[0] != null and .[1] != null)))), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
eval SORT_BY_STY  # ORD: the panels by family, the reference first
title(i) = TITLE[i + 1]
pts(i, j) = sprintf("$P%d_%d", i, j)
set terminal pngcairo size 1600,1500 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
set xlabel "z".U
set ylabel "dz/dt".U
# One colour per initial state: Paul Tol's muted palette, black for the tenth.
array STATE_RGB[10] = ["#332288", "#88CCEE", "#44AA99", "#117733", "#999933", "#DDCC77", "#CC6677", "#882255", "#AA4499", "#000000"]
set xrange [-1.6:1.6]
set yrange [-1.6:1.6]
set size ratio -1
unset key
set multiplot layout 3,4 title sprintf("Poincare sections of %s: (z, dz/dt) at each maximum of y, h = 2 sin(pi/40), 10 initial states on H = 3/2, H_y = 1/2", scene) noenhanced
do for [k=1:N] {
  i = ORD[k] - 1
  set title title(i) noenhanced
  plot for [j=0:S-1] pts(i, j) u 1:2 w p pt 7 ps 0.12 lc rgb STATE_RGB[j % 10 + 1]
}
unset multiplot
