# Study 3: max |E - E0| over T = 200 against h, failures marked, and the largest
# stable h per method.
# Called as gnuplot -e "file='results/stability.json'; scene='particle'; out='plots/stability_particle.png'" plots/stability.gp
load "plots/style.gp"
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   N; LABEL, STY[i + 1] of method i (label, method_ls(label));
#   $OK<i>, $ENERGY<i>, $SOLVE<i>, $NONFINITE<i>: h, max |E - E0| of the runs of
#   method i that were ok, or failed on the energy threshold, in the solve, or
#   with a non-finite state;
#   $LARGEST: label, largest stable h and largest surviving h of every method
#   (0.005, the bottom of the axis, where there is none).
load jq_script(sprintf("--arg scene '%s'", scene), \
  'def runs($i; $name; status): jq_block("$\($name)\($i)"; .runs[] | select(status) | [.h, .max_abs_energy_error]); ' . \
  '.scenes[$scene].methods | "N = \(length)", "array LABEL[N]", "array STY[N]", ' . \
  '(to_entries[] | .key as $i | .value ' . \
  ' | "LABEL[\($i + 1)] = \(.label | gp)", "STY[\($i + 1)] = method_ls(\(.label | gp))", ' . \
  '   runs($i; "OK"; .status == "ok"), runs($i; "ENERGY"; .failure.kind == "energy"), ' . \
  '   runs($i; "SOLVE"; .failure.kind == "solve"), runs($i; "NONFINITE"; .failure.kind == "non-finite")), ' . \
  'jq_block("$LARGEST"; .[] | [.label, (.largest_stable_h // 0.005), (.largest_surviving_h // 0.005)]), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
eval SORT_BY_STY  # ORD: the methods by family
label(i) = LABEL[i]
sty(i) = STY[i]
# $BARS: row k of the bar chart (methods by family, top to bottom), label and
# the largest stable and surviving h.
array LS[N]
array LV[N]
set datafile separator "\t"
stats $LARGEST u (LS[int($0) + 1] = $2, LV[int($0) + 1] = $3) nooutput
set print $BARS
do for [k=1:N] { print sprintf("%d\t%s\t%g\t%g", N + 1 - k, label(ORD[k]), LS[ORD[k]], LV[ORD[k]]) }
unset print
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,1000 enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set multiplot title sprintf("Stability sweep, T = 200 (%s): failure = solve not converged, non-finite state, or |E − E_0| > |E_0|", plain(scene))
set tmargin at screen 0.90
set bmargin at screen 0.34
set lmargin at screen 0.07
set rmargin at screen 0.60
set logscale xy
set format x "%g"
set format y "10^{%L}"
set xlabel "h".U
set ylabel "max |E − E_0| over the run".U
set yrange [1e-10:1e30]
set key at screen 0.01, 0.235 left top vertical maxrows 10 Left reverse font ",9" width -7 samplen 3.5 nobox noopaque
set title "error as h grows: line and marker, runs that stayed ok; +, x, *: failed runs"
plot for [k=1:N] sprintf("$OK%d", ORD[k] - 1) u 1:2 w lp ls sty(ORD[k]) notitle, \
     for [k=1:N] keyentry w lp ls sty(ORD[k]) t label(ORD[k]), \
     for [k=1:N] sprintf("$ENERGY%d", ORD[k] - 1) u 1:2 w p ls sty(ORD[k]) pt 1 ps 1.5 notitle, \
     for [k=1:N] sprintf("$SOLVE%d", ORD[k] - 1) u 1:2 w p ls sty(ORD[k]) pt 2 ps 1.5 notitle, \
     for [k=1:N] sprintf("$NONFINITE%d", ORD[k] - 1) u 1:2 w p ls sty(ORD[k]) pt 3 ps 1.5 notitle, \
     keyentry w p pt 1 ps 1.5 lc rgb "black" t "failed: |E − E_0| > |E_0|", \
     keyentry w p pt 2 ps 1.5 lc rgb "black" t "failed: solve not converged", \
     keyentry w p pt 3 ps 1.5 lc rgb "black" t "failed: non-finite state"
# Horizontal bars: every label readable on the y axis.
set lmargin at screen 0.80
set rmargin at screen 0.98
set bmargin at screen 0.14
unset logscale y
set yrange [0.4:N + 0.6]
set ytics 1 font ",9" nomirror noenhanced
set grid noytics
set format y ""
set xrange [0.005:20]
set format x "%g"
set xlabel "largest h".U
unset ylabel
set title "largest h per method (no bar: none)"
set style fill solid 0.9 border -1
set key at screen 0.80, 0.065 left top vertical Left reverse font ",9" samplen 2 nobox noopaque
plot $BARS u (sqrt(0.005 * $3)):($1 + 0.19):(0.005):($3):($1):($1 + 0.38):ytic(2) w boxxyerror lc rgb "#505050" t "stable (|E − E_0| ≤ |E_0|)", \
     '' u (0.005):($1 - 0.19):(0.005):($4):($1 - 0.38):($1) w boxxyerror lc rgb "#C8C8C8" t "survives to T (solves converge, finite)"
unset multiplot
