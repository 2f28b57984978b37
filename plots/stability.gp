# Study 3: max |E - E0| over T = 200 against h, failures marked, and the largest
# stable h per method.
# Called as gnuplot -e "file='results/stability.json'; scene='particle'; out='plots/stability_particle.png'" plots/stability.gp
load "plots/style.gp"
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,560 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
# Line style of method i: 10 + its fixed style (plots/style.gp).
sty_of(i) = 10 + int(system(sprintf("jq -r '.scenes.%s.methods[%d].style // 12' %s", scene, i, file)))
N = int(system(sprintf("jq '.scenes.%s.methods | length' %s", scene, file)))
label_of(i) = system(sprintf("jq -r '.scenes.%s.methods[%d].label' %s", scene, i, file))
# Each method's label and style read once (a jq call each), not per use.
array LABEL[N]
array STY[N]
do for [j=1:N] { LABEL[j] = label_of(j - 1); STY[j] = sty_of(j - 1) }
label(i) = LABEL[i + 1]
sty(i) = STY[i + 1]
# h, max |E - E0| for runs of method i with the given status filter
runs(i, filter) = sprintf("< jq -r '.scenes.%s.methods[%d].runs[] | select(%s) | [.h, .max_abs_energy_error] | @tsv' %s", scene, i, filter, file)
set datafile separator "\t"
set multiplot layout 1,2 title sprintf("Stability sweep, T = 200 (%s): failure = solve not converged, non-finite state, or |E - E_0| > |E_0|", scene)
set logscale xy
set format y "10^{%L}"
set xlabel "h"
set ylabel "max |E - E_0| over the run"
set yrange [1e-10:1e30]
set key top left font ",8" spacing 0.9
set title "error as h grows (filled: ok; open circle: energy threshold; x: solve failed; triangle: non-finite)"
plot for [i=0:N-1] runs(i, ".status == \"ok\"") u 1:2 w lp ls sty(i) pt 7 ps 0.6 notitle, \
     for [i=0:N-1] 1/0 w lp ls sty(i) ps 0.6 t label(i), \
     for [i=0:N-1] runs(i, ".failure.kind == \"energy\"") u 1:2 w p ls sty(i) pt 6 ps 0.9 notitle, \
     for [i=0:N-1] runs(i, ".failure.kind == \"solve\"") u 1:2 w p ls sty(i) pt 2 ps 1.4 notitle, \
     for [i=0:N-1] runs(i, ".failure.kind == \"non-finite\"") u 1:2 w p ls sty(i) pt 8 ps 1.4 notitle
unset logscale y
set logscale y
set format y "%g"
set yrange [0.005:20]
set ylabel "h"
set title "largest h: stable within the energy threshold (solid), surviving to T at all (light)"
set style data histograms
set style histogram clustered gap 1
set style fill solid 0.8 border -1
set boxwidth 0.9
unset logscale x
set xtics rotate by -30 font ",9"
set xlabel ""
set key top right
plot sprintf("< jq -r '.scenes.%s.methods[] | [.label, (.largest_stable_h // 0.005), (.largest_surviving_h // 0.005)] | @tsv' %s", scene, file) \
       u 2:xtic(1) lc rgb "#1f77b4" t "stable (|E - E_0| <= |E_0|)", '' u 3 lc rgb "#aec7e8" t "survives (solves converge, finite)"
unset multiplot
