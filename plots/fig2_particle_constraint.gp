# Paper Figure 2: constraint value omega(q) v = zdot - y xdot along each method
# (DLA velocities are central differences (q_{k+1} - q_{k-1}) / 2h), and the
# DLA's discrete constraint omega_d(q_k, q_{k+1}) (eq. 13), which it enforces.
# Inputs: results/particle_fig12_{dla,rk4,benchmark}.json
load "plots/style.gp"
set output "plots/fig2_particle_constraint.png"
dla = "results/particle_fig12_dla.json"
rk4 = "results/particle_fig12_rk4.json"
ref = "results/particle_fig12_benchmark.json"
set multiplot layout 2,1 title "Figure 2: nonholonomic particle, constraint value {/Symbol w}(q)v (h = 0.2)"
set xlabel "t"
set ylabel "{/Symbol w}(q) v"
set xrange [0:40]
set title "signed, first 40 time units"
plot col(dla, ".constraint | map(.[0])") u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
     col(rk4, ".constraint | map(.[0])") u 1:2 w l ls 2 t "RK4", \
     col(ref, ".constraint | map(.[0])") u 1:2 w l ls 3 t "benchmark"
set autoscale x
set logscale y
set format y "10^{%L}"
set yrange [1e-18:1]
set ylabel "|{/Symbol w}(q) v|"
set title "magnitude, whole run (log scale)"
set key at graph 0.98, graph 0.66 right top
plot col(dla, ".constraint | map(.[0] | fabs)") u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
     col(rk4, ".constraint | map(.[0] | fabs)") u 1:2 w l ls 2 t "RK4", \
     col(ref, ".constraint | map(.[0] | fabs)") u 1:2 w l ls 3 t "benchmark", \
     col(dla, ".discrete_constraint | map(.[0] | fabs)") u 1:2 w p pt 7 ps 0.2 lc rgb "#17becf" t "DLA: its discrete constraint {/Symbol w}_d(q_k, q_{k+1})"
unset multiplot
