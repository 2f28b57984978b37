# Study 1: global error at T against h, log-log, with reference slopes.
# Called as gnuplot -e "file='results/convergence.json'; scene='particle'; out='plots/convergence_particle.png'" plots/convergence.gp
load "plots/style.gp"
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   N; LABEL, FAMILY, STY[i + 1] of method i (label with its fitted order, family,
#   method_ls(label); fitted_order is null where no two errors above round-off
#   remain: "p = -");
#   $M<i>_0, $M<i>_1: h and error of method i if its family is not (0) or is (1)
#   "isolation", rows without an error dropped.
load jq_script(sprintf("--arg scene '%s'", scene), \
  '.scenes[$scene].methods | "N = \(length)", "array LABEL[N]", "array FAMILY[N]", "array STY[N]", ' . \
  '(to_entries[] | .key as $i | .value ' . \
  ' | "LABEL[\($i + 1)] = \("\(.label) (p = \(.fitted_order | if type == "number" then (. * 100 | round / 100) else "-" end))" | gp)", ' . \
  '   "FAMILY[\($i + 1)] = \(.family | gp)", "STY[\($i + 1)] = method_ls(\(.label | gp))", ' . \
  '   ((0, 1) as $want | jq_block("$M\($i)_\($want)"; ' . \
  '      select((.family == "isolation") == ($want == 1)) | [.h, .error] | transpose[] | select(.[1] != null)))), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
label(i) = LABEL[i + 1]
family(i) = FAMILY[i + 1]
sty(i) = STY[i + 1]
# Columns h, error of method i if its family is (want = 1) or is not (want = 0) "isolation".
m(i, want) = sprintf("$M%d_%d", i, want)
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1400,620 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
set logscale xy
set format y "10^{%L}"
set xlabel "h"
set ylabel "max_i |q_i(T) - q_{ref,i}(T)|"
set key bottom right font ",9" spacing 0.9
set xrange [0.0005:0.3]
set yrange [1e-14:10]
ref(h, c, p) = c * h**p
set multiplot layout 1,2 title sprintf("Convergence at T = 10 (%s), against CVODE at tol 1e-13", scene)
set title "DLA (alpha, symmetric) and RK4"
set style data linespoints
plot for [i=0:N-1] m(i, 0) u 1:2 w lp ls sty(i) ps 0.8 t (family(i) eq "isolation" ? "" : label(i)), \
     ref(x, 1, 1) w l dt 2 lc rgb "#888888" t "h^1", ref(x, 0.5, 2) w l dt 3 lc rgb "#888888" t "h^2", \
     ref(x, 0.05, 4) w l dt 4 lc rgb "#888888" t "h^4"
set title "what limits alpha != 1/2: L_d and omega_d of different alpha, and the start p_0"
plot for [i=0:N-1] m(i, 1) u 1:2 w lp pt (i % 7 + 4) ps 0.8 t (family(i) eq "isolation" ? label(i) : ""), \
     ref(x, 1, 1) w l dt 2 lc rgb "#888888" t "h^1", ref(x, 0.5, 2) w l dt 3 lc rgb "#888888" t "h^2"
unset multiplot
