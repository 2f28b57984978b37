# Study 5: Poincare sections (z, zd) once per y period, one panel per method,
# one colour per initial state.
# Called as gnuplot -e "file='results/poincare.json'; scene='contact_oscillator'; out='plots/poincare_contact_oscillator.png'" plots/poincare.gp
load "plots/style.gp"
set terminal pngcairo size 1600,1500 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
N = int(system(sprintf("jq '.scenes.%s.methods | length' %s", scene, file)))
S = int(system(sprintf("jq '.scenes.%s.initial_states | length' %s", scene, file)))
pts(i, j) = sprintf("< jq -r '.scenes.%s.methods[%d].runs[%d] | [.z, .zd] | transpose[] | select(.[0] != null and .[1] != null) | @tsv' %s", scene, i, j, file)
title(i) = system(sprintf("jq -r '.scenes.%s.methods[%d] | \"\\(.label): thickness x\\(.summary.median_thickness_ratio // \"-\" | if type == \"number\" then (. * 100 | round / 100) else . end), max |R-R_0| \\(.summary.max_abs_R_error | . * 1e4 | round / 1e4)\"' %s", scene, i, file))
set xlabel "z"
set ylabel "dz/dt"
set xrange [-1.6:1.6]
set yrange [-1.6:1.6]
set size ratio -1
unset key
set multiplot layout 3,4 title sprintf("Poincare sections of %s: (z, dz/dt) at each maximum of y, h = 2 sin(pi/40), 10 initial states on H = 3/2, H_y = 1/2", scene) noenhanced
do for [i=0:N-1] {
  set title title(i) noenhanced
  plot for [j=0:S-1] pts(i, j) u 1:2 w dots lc j+1
}
unset multiplot
