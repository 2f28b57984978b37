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
set terminal pngcairo size 1000,760 enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set multiplot title label.", energy (h = 0.2)"
set xlabel "t".U
set ylabel "E".U
# One legend for both panels, above them (never on the data); the reference first.
set key at screen 0.5, 0.935 center top horizontal maxcols 3 Left reverse font ",10" samplen 3 width 2 nobox noopaque
P = '$ref u 1:2 w l ls method_ls("reference") t "reference (CVODE Adams, tol 1e-12)", ' . \
    '$dla u 1:2 w l ls method_ls("dla a=0.5") t "DLA, {/Symbol a} = 1/2", ' . \
    '$rk4 u 1:2 w l ls method_ls("rk4") t "RK4"'
eval stack(1, 2, 0.84, 0.08, 0.15)
set title "whole run"
plot @P
unset key
eval stack(2, 2, 0.84, 0.08, 0.15)
set xrange [0:40]
set title "first 40 time units"
plot @P
unset multiplot
