# Companion to Figures 2 and 4: |omega_a(q) v| along the paper's
# DLA (central-difference velocities), mp06 and its triple jump (v_k = V(q_k, p_k),
# which they keep in the constraint distribution), RK4 and the reference
# solution, h = 0.2, log scale.  Exact zeros are not drawn.  Called as
# plots/constraint.gp (stem, out, label, m).
load "plots/style.gp"
dla = stem."_dla.json"
mp = stem."_mp06.json"
mptj = stem."_mp06tj.json"
rk4 = stem."_rk4.json"
ref = stem."_benchmark.json"
# $<run>_<a>: t and |omega_a(q) v| along each run (dla, rk4, ref, mp, mptj),
# a = 1..m, from one jq pass over the five files (jq_script, plots/style.gp).
load jq_script(sprintf("-n --argjson m %d", m), \
  '(("dla", "rk4", "ref", "mp", "mptj") as $run | input | range($m) as $a ' . \
  ' | jq_block("$\($run)_\($a + 1)"; [.t, (.constraint | map(.[$a] | fabs))] | transpose[])), ' . \
  '"jq_ok = 1"', sprintf("%s %s %s %s %s", dla, rk4, ref, mp, mptj))
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s_*.json, no figure drawn", out, stem) }
set output out
set terminal pngcairo size 1000,(400 * m)
set multiplot layout m,1 title label.", constraint values (h = 0.2), methods after the paper"
set xlabel "t"
set logscale y
set format y "10^{%L}"
set yrange [1e-19:10]
set key tmargin center horizontal maxrows 2 noopaque nobox
do for [a = 0:m-1] {
  set title sprintf("|{/Symbol w}_%d(q) v|, whole run (log scale)", a + 1)
  set ylabel sprintf("|{/Symbol w}_%d(q) v|", a + 1)
  plot sprintf("$dla_%d", a + 1) u 1:2 w l ls method_ls("dla a=0.5") t "DLA, {/Symbol a} = 1/2", \
       sprintf("$rk4_%d", a + 1) u 1:2 w l ls method_ls("rk4") t "RK4", \
       sprintf("$ref_%d", a + 1) u 1:2 w l ls method_ls("reference") t "reference", \
       sprintf("$mp_%d", a + 1) u 1:2 w p pt 7 ps 0.3 lc rgb "#ff7f0e" t "mp06", \
       sprintf("$mptj_%d", a + 1) u 1:2 w p pt 5 ps 0.3 lc rgb "#a63603" t "mp06, triple jump"
}
unset multiplot
