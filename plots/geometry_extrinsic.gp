# The Constrained Coordinate Formulation (eq. 17).  Robot: the intrinsic DLA
# (angles) against the extrinsic one (unit vectors, |u| = 1 as holonomic
# constraints), energy and convergence; circle (Remark 3.3): the omega-DLA and
# the eq.-17 DLA.
# Called as gnuplot -e "file='results/geometry.json'; out='plots/geometry_extrinsic.png'" plots/geometry_extrinsic.gp
load "plots/style.gp"
set terminal pngcairo size 1500,520 enhanced font "DejaVu Sans,10" linewidth 1.2
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   oi, oe, the fitted orders of the intrinsic and extrinsic DLA;
#   $robot_intrinsic, $robot_extrinsic: t and E - E_0 of the robot's runs;
#   $circle_omega, $circle_g: t and E - E_0 of the circle's runs;
#   $conv_intrinsic, $conv_extrinsic: h and the robot's error at T.
load jq_script("", \
  '"oi = real(\(.extrinsic.convergence.order_intrinsic | gp))", ' . \
  '"oe = real(\(.extrinsic.convergence.order_extrinsic | gp))", ' . \
  '(.extrinsic | ("intrinsic", "extrinsic") as $k | jq_block("$robot_\($k)"; .[$k] | [.t, .energy_error] | transpose[])), ' . \
  '(.holonomic.circle | ("omega", "g") as $k | jq_block("$circle_\($k)"; .[$k] | [.t, .energy_error] | transpose[])), ' . \
  '(.extrinsic.convergence | ("intrinsic", "extrinsic") as $k | jq_block("$conv_\($k)"; [.h, .[$k]] | transpose[])), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
set output out
set style data lines
set multiplot layout 1,3 title "Extrinsic (unit vectors, eq. 17) against intrinsic (angles) DLA, midpoint"
set title "robot, h = 0.2: E - E_0"
set xlabel "t"
set xrange [0:30]
set key bottom right font ",8"
plot $robot_intrinsic u 1:2 ls 1 t "intrinsic (angles)", \
     $robot_extrinsic u 1:2 lc rgb "#ff7f0e" t "extrinsic (unit vectors)"
set title "robot: max-norm error of q(T = 2) against the exact reduced flow"
set xlabel "h"
set xrange [*:*]
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set key top left font ",8"
plot $conv_intrinsic u 1:2 w lp ls 1 pt 7 t sprintf("intrinsic, order %.2f", oi), \
     $conv_extrinsic u 1:2 w lp lc rgb "#ff7f0e" pt 5 t sprintf("extrinsic, order %.2f", oe)
unset logscale
set format x "%g"
set format y "%g"
set title "circle (Remark 3.3), h = 0.1: E - E_0"
set xlabel "t"
set xrange [0:100]
set key bottom right font ",8"
plot $circle_omega u 1:2 ls 1 lw 2.5 t "DLA with {/Symbol w} = q^T", \
     $circle_g u 1:2 lc rgb "black" dt 2 t "DLA with g = (|q|^2 - 1)/2 (eq. 17)"
unset multiplot
