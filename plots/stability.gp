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
label(i) = LABEL[i + 1]
sty(i) = STY[i + 1]
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,560 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
set datafile separator "\t"
set multiplot layout 1,2 title sprintf("Stability sweep, T = 200 (%s): failure = solve not converged, non-finite state, or |E - E_0| > |E_0|", scene)
set logscale xy
set format y "10^{%L}"
set xlabel "h"
set ylabel "max |E - E_0| over the run"
set yrange [1e-10:1e30]
set key top left font ",8" spacing 0.9
set title "error as h grows (filled: ok; open circle: energy threshold; x: solve failed; triangle: non-finite)"
plot for [i=0:N-1] sprintf("$OK%d", i) u 1:2 w lp ls sty(i) pt 7 ps 0.6 notitle, \
     for [i=0:N-1] 1/0 w lp ls sty(i) ps 0.6 t label(i), \
     for [i=0:N-1] sprintf("$ENERGY%d", i) u 1:2 w p ls sty(i) pt 6 ps 0.9 notitle, \
     for [i=0:N-1] sprintf("$SOLVE%d", i) u 1:2 w p ls sty(i) pt 2 ps 1.4 notitle, \
     for [i=0:N-1] sprintf("$NONFINITE%d", i) u 1:2 w p ls sty(i) pt 8 ps 1.4 notitle
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
plot $LARGEST u 2:xtic(1) lc rgb "#1f77b4" t "stable (|E - E_0| <= |E_0|)", '' u 3 lc rgb "#aec7e8" t "survives (solves converge, finite)"
unset multiplot
