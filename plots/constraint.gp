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
set output out
set terminal pngcairo size 1000,(350 * (m + 1))
set multiplot layout (m + 1),1 title label.", constraint values (h = 0.2)"
set xlabel "t"
set xrange [0:40]
set title "signed {/Symbol w}_1(q) v, first 40 time units"
set ylabel "{/Symbol w}_1(q) v"
set key top left box opaque
plot $dla_signed u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
     $rk4_signed u 1:2 w l ls 2 t "RK4", \
     $ref_signed u 1:2 w l ls 3 t "benchmark"
set autoscale x
set logscale y
set format y "10^{%L}"
set yrange [1e-18:10]
set key tmargin center horizontal maxrows 2 noopaque nobox
do for [a = 0:m-1] {
  set title sprintf("|{/Symbol w}_%d(q) v|, whole run (log scale)", a + 1)
  set ylabel sprintf("|{/Symbol w}_%d(q) v|", a + 1)
  plot sprintf("$dla_%d", a + 1) u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
       sprintf("$rk4_%d", a + 1) u 1:2 w l ls 2 t "RK4", \
       sprintf("$ref_%d", a + 1) u 1:2 w l ls 3 t "benchmark", \
       sprintf("$dla_discrete_%d", a + 1) u 1:2 w p pt 7 ps 0.2 lc rgb "#17becf" t "DLA: its discrete constraint {/Symbol w}_d(q_k, q_{k+1})"
}
unset multiplot
