# Study: the global error max_i |q_i(t) - q_ref,i(t)| against t, log-log, per
# method, with its fitted growth exponent over [T/100, T] in the key (slope 1:
# linear phase error; 2: quadratic).
# Called as gnuplot -e "file='results/global_error.json'; scene='particle'; out='plots/global_error_particle.png'" plots/global_error.gp
load "plots/style.gp"
# From one jq pass (jq_script, plots/style.gp): N; LABEL, STY[i + 1] of method i
# (label with its exponent, method_ls(label)); H, T, REF; $ERR<i>: t and the error.
load jq_script(sprintf("--arg scene '%s'", scene), \
  '.scenes[$scene] as $s | "N = \($s.methods | length)", "array LABEL[N]", "array STY[N]", ' . \
  '"H = \($s.h | gp)", "T = real(\($s.T | gp))", "REF = \($s.reference | gp)", ' . \
  '($s.methods | to_entries[] | .key as $i | .value ' . \
  ' | "LABEL[\($i + 1)] = \("\(.label): t^\(if .growth_exponent == null then "-" else (.growth_exponent * 100 | round / 100) end)" | gp)", ' . \
  '   "STY[\($i + 1)] = method_ls(\(.label | gp))", ' . \
  '   jq_block("$ERR\($i)"; [.t, .error] | transpose[] | select(.[1] > 0))), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
eval SORT_BY_STY  # ORD: the methods by family
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1200,700 enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set datafile separator "\t"
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "t".U
set ylabel "max_i |q_i(t) − q_{ref,i}(t)|".U
set key outside right top vertical Left reverse font ",10" samplen 3.5 nobox noopaque
set title sprintf("Global error, h = %s, T = %.4g (%s; reference: %s)", H, T, scene, REF) noenhanced
# Lines, their markers every 5 points staggered per method, one key entry each.
plot for [k=1:N] sprintf("$ERR%d", ORD[k] - 1) u 1:2 w l ls STY[ORD[k]] notitle, \
     for [k=1:N] sprintf("$ERR%d", ORD[k] - 1) every 5::(k % 5) u 1:2 w p ls STY[ORD[k]] notitle, \
     for [k=1:N] keyentry w lp ls STY[ORD[k]] t LABEL[ORD[k]]
