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
eval SORT_BY_STY  # ORD: the methods by family, the legend grouped so
label(i) = LABEL[i + 1]
family(i) = FAMILY[i + 1]
sty(i) = STY[i + 1]
# Columns h, error of method i if its family is (want = 1) or is not (want = 0) "isolation".
m(i, want) = sprintf("$M%d_%d", i, want)
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1600,1000 enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "h".U
set ylabel "max_i |q_i(T) − q_{ref,i}(T)|".U
set key Left reverse vertical font ",9" spacing 1.0 width -7 samplen 3.5 nobox noopaque
set xrange [0.0005:0.3]
set yrange [1e-14:10]
ref(h, c, p) = c * h**p
# The panels over the top 70 %, their legends below them (never on the data).
set multiplot title sprintf("Convergence at T = 10 (%s), against CVODE at tol 1e-13", plain(scene))
set tmargin at screen 0.92
set bmargin at screen 0.31
set lmargin at screen 0.06
set rmargin at screen 0.56
set key at screen 0.01, 0.225 left top maxrows 10
set title "DLA ({/Symbol a}, symmetric), mp06, discrete gradient, SPARK and RK4"
plot for [k=1:N] m(ORD[k] - 1, 0) u 1:2 w lp ls STY[ORD[k]] t (family(ORD[k] - 1) eq "isolation" ? "" : label(ORD[k] - 1)), \
     ref(x, 1, 1) w l dt 2 lw 1 lc rgb "#888888" t "slope h^1", ref(x, 0.5, 2) w l dt 3 lw 1 lc rgb "#888888" t "slope h^2", \
     ref(x, 0.05, 4) w l dt 4 lw 1 lc rgb "#888888" t "slope h^4"
set lmargin at screen 0.66
set rmargin at screen 0.98
set key at screen 0.715, 0.225 left top maxrows 10
set title "what limits {/Symbol a} ≠ 1/2: L_d and {/Symbol w}_d of other {/Symbol a}, the start p_0"
plot for [k=1:N] m(ORD[k] - 1, 1) u 1:2 w lp ls STY[ORD[k]] t (family(ORD[k] - 1) eq "isolation" ? label(ORD[k] - 1) : ""), \
     ref(x, 1, 1) w l dt 2 lw 1 lc rgb "#888888" t "slope h^1", ref(x, 0.5, 2) w l dt 3 lw 1 lc rgb "#888888" t "slope h^2"
unset multiplot
