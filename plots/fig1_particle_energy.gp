# Paper Figure 1: energy of the nonholonomic particle, DLA (alpha = 1/2), RK4 and
# the benchmark at h = 0.2.  Inputs: results/particle_fig12_{dla,rk4,benchmark}.json
load "plots/style.gp"
set output "plots/fig1_particle_energy.png"
dla = "results/particle_fig12_dla.json"
rk4 = "results/particle_fig12_rk4.json"
ref = "results/particle_fig12_benchmark.json"
set multiplot layout 2,1 title "Figure 1: nonholonomic particle, energy (h = 0.2)"
set xlabel "t"
set ylabel "E"
set key bottom left
plot col(dla, ".energy") u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
     col(rk4, ".energy") u 1:2 w l ls 2 t "RK4", \
     col(ref, ".energy") u 1:2 w l ls 3 t "benchmark (CVODE Adams, tol 1e-12)"
set xrange [0:40]
set title "first 40 time units"
set yrange [1.78:1.915]
set key bottom right horizontal
replot
unset multiplot
