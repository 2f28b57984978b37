# Paper Figures 2 and 4: constraint values omega_a(q) v along each method
# (DLA velocities are central differences (q_{k+1} - q_{k-1}) / 2h), and the
# DLA's discrete constraint omega_d(q_k, q_{k+1}) (eq. 13), which it enforces.
# Called with stem, out, label (as plots/energy.gp) and m, the number of constraints.
load "plots/style.gp"
dla = stem."_dla.json"
rk4 = stem."_rk4.json"
ref = stem."_benchmark.json"
# From one jq pass over the three files (jq_script, plots/style.gp), for each
# run (dla, rk4, ref): $<run>_signed, t and omega_1(q) v;  $<run>_<a>, t and
# |omega_a(q) v| (a = 1..m);  and $dla_discrete_<a>, t and |omega_d(q_k, q_{k+1})|_a.
load jq_script(sprintf("-n --argjson m %d", m), \
  '(("dla", "rk4", "ref") as $run | input ' . \
  ' | jq_block("$\($run)_signed"; [.t, (.constraint | map(.[0]))] | transpose[]), ' . \
  '   (range($m) as $a | jq_block("$\($run)_\($a + 1)"; [.t, (.constraint | map(.[$a] | fabs))] | transpose[])), ' . \
  '   (select($run == "dla") | range($m) as $a ' . \
  '    | jq_block("$dla_discrete_\($a + 1)"; [.t, (.discrete_constraint | map(.[$a] | fabs))] | transpose[]))), ' . \
  '"jq_ok = 1"', sprintf("%s %s %s", dla, rk4, ref))
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s_*.json, no figure drawn", out, stem) }
H = 330 * (m + 1) + 90
set terminal pngcairo size 1000,H enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set multiplot title label.", constraint values (h = 0.2)"
set xlabel "t".U
# One legend for all panels, above them (never on the data); the reference first.
TOP = 1 - 125.0 / H
GAP = 120.0 / H
set key at screen 0.5, 1 - 40.0 / H center top horizontal maxcols 2 Left reverse font ",10" samplen 3 width 2 nobox noopaque
eval stack(1, m + 1, TOP, 60.0 / H, GAP)
set xrange [0:40]
set title "signed {/Symbol w}_1(q) v, first 40 time units"
set ylabel "{/Symbol w}_1(q) v".U
plot $ref_signed u 1:2 w l ls method_ls("reference") t "reference (CVODE Adams)", \
     $dla_signed u 1:2 w l ls method_ls("dla a=0.5") t "DLA, {/Symbol a} = 1/2", \
     $rk4_signed u 1:2 w l ls method_ls("rk4") t "RK4", \
     keyentry w p pt 7 ps 0.8 lc rgb "#003D66" t "DLA: its discrete constraint {/Symbol w}_d(q_k, q_{k+1})"
unset key
set autoscale x
set logscale y
set format y "10^{%L}"
set yrange [1e-18:10]
do for [a = 0:m-1] {
  eval stack(a + 2, m + 1, TOP, 60.0 / H, GAP)
  set title sprintf("|{/Symbol w}_%d(q) v|, whole run (log scale)", a + 1)
  set ylabel sprintf("|{/Symbol w}_%d(q) v|", a + 1).U
  plot sprintf("$ref_%d", a + 1) u 1:2 w l ls method_ls("reference"), \
       sprintf("$dla_%d", a + 1) u 1:2 w l ls method_ls("dla a=0.5"), \
       sprintf("$rk4_%d", a + 1) u 1:2 w l ls method_ls("rk4"), \
       sprintf("$dla_discrete_%d", a + 1) u 1:2 w p pt 7 ps 0.2 lc rgb "#003D66"
}
unset multiplot
