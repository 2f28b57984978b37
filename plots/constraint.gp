# Paper Figures 2 and 4: constraint values omega_a(q) v along each method
# (DLA velocities are central differences (q_{k+1} - q_{k-1}) / 2h), and the
# DLA's discrete constraint omega_d(q_k, q_{k+1}) (eq. 13), which it enforces.
# Called with stem, out, label (as plots/energy.gp) and m, the number of constraints.
load "plots/style.gp"
set output out
dla = stem."_dla.json"
rk4 = stem."_rk4.json"
ref = stem."_benchmark.json"
set terminal pngcairo size 1000,(350 * (m + 1))
set multiplot layout (m + 1),1 title label.", constraint values (h = 0.2)"
set xlabel "t"
set xrange [0:40]
set title "signed {/Symbol w}_1(q) v, first 40 time units"
set ylabel "{/Symbol w}_1(q) v"
set key top left box opaque
plot col(dla, ".constraint | map(.[0])") u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
     col(rk4, ".constraint | map(.[0])") u 1:2 w l ls 2 t "RK4", \
     col(ref, ".constraint | map(.[0])") u 1:2 w l ls 3 t "benchmark"
set autoscale x
set logscale y
set format y "10^{%L}"
set yrange [1e-18:10]
set key tmargin center horizontal maxrows 2 noopaque nobox
do for [a = 0:m-1] {
  set title sprintf("|{/Symbol w}_%d(q) v|, whole run (log scale)", a + 1)
  set ylabel sprintf("|{/Symbol w}_%d(q) v|", a + 1)
  f = sprintf(".constraint | map(.[%d] | fabs)", a)
  g = sprintf(".discrete_constraint | map(.[%d] | fabs)", a)
  plot col(dla, f) u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
       col(rk4, f) u 1:2 w l ls 2 t "RK4", \
       col(ref, f) u 1:2 w l ls 3 t "benchmark", \
       col(dla, g) u 1:2 w p pt 7 ps 0.2 lc rgb "#17becf" t "DLA: its discrete constraint {/Symbol w}_d(q_k, q_{k+1})"
}
unset multiplot
