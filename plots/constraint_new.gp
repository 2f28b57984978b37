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
H = 370 * m + 130
set terminal pngcairo size 1000,H enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set multiplot title label.", constraint values (h = 0.2), methods after the paper"
set xlabel "t".U
set logscale y
set format y "10^{%L}"
set yrange [1e-19:10]
# One legend for all panels, above them (never on the data); the reference first.
set key at screen 0.5, 1 - 40.0 / H center top horizontal maxcols 3 Left reverse font ",10" samplen 3 width 2 nobox noopaque
# The two mp06 point clouds overlap: the triple jump in a dark shade of the mp06 hue.
MP_DARK = "#7A3500"
do for [a = 0:m-1] {
  eval stack(a + 1, m, 1 - 125.0 / H, 60.0 / H, 120.0 / H)
  set title sprintf("|{/Symbol w}_%d(q) v|, whole run (log scale)", a + 1)
  set ylabel sprintf("|{/Symbol w}_%d(q) v|", a + 1).U
  plot sprintf("$ref_%d", a + 1) u 1:2 w l ls method_ls("reference") t "reference (CVODE Adams)", \
       sprintf("$dla_%d", a + 1) u 1:2 w l ls method_ls("dla a=0.5") t "DLA, {/Symbol a} = 1/2", \
       sprintf("$mptj_%d", a + 1) u 1:2 w p ls method_ls("mp06+triple_jump") pt 9 ps 0.4 lc rgb MP_DARK notitle, \
       sprintf("$mp_%d", a + 1) u 1:2 w p ls method_ls("mp06") pt 7 ps 0.3 notitle, \
       keyentry w p ls method_ls("mp06") pt 7 ps 0.9 t "mp06", \
       keyentry w p ls method_ls("mp06+triple_jump") pt 9 ps 1.0 lc rgb MP_DARK t "mp06, triple jump", \
       sprintf("$rk4_%d", a + 1) u 1:2 w l ls method_ls("rk4") t "RK4"
  unset key
}
unset multiplot
