# Paper Figures 1 and 3: energy along the DLA (alpha = 1/2), RK4 and the
# benchmark at h = 0.2.  Called as
#   gnuplot -e "stem='results/particle_fig12'; out='plots/fig1_particle_energy.png'; label='Figure 1: nonholonomic particle'" plots/energy.gp
# reading stem_{dla,rk4,benchmark}.json.
load "plots/style.gp"
dla = stem."_dla.json"
rk4 = stem."_rk4.json"
ref = stem."_benchmark.json"
# $dla, $rk4, $ref: t and E of each run, from one jq pass over the three files
# (jq_script, plots/style.gp; it also spares the replot a second pass).
load jq_script("-n", \
  '(("dla", "rk4", "ref") as $name | input | jq_block("$\($name)"; [.t, .energy] | transpose[])), ' . \
  '"jq_ok = 1"', sprintf("%s %s %s", dla, rk4, ref))
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s_*.json, no figure drawn", out, stem) }
set output out
set multiplot layout 2,1 title label.", energy (h = 0.2)"
set xlabel "t"
set ylabel "E"
set key bottom left
plot $dla u 1:2 w l ls 1 t "DLA, {/Symbol a} = 1/2", \
     $rk4 u 1:2 w l ls 2 t "RK4", \
     $ref u 1:2 w l ls 3 t "benchmark (CVODE Adams, tol 1e-12)"
set xrange [0:40]
set title "first 40 time units"
set key bottom right horizontal
replot
unset multiplot
