# The Constrained Coordinate Formulation (eq. 17).  Robot: the intrinsic DLA
# (angles) against the extrinsic one (unit vectors, |u| = 1 as holonomic
# constraints), energy and convergence; circle (Remark 3.3): the omega-DLA and
# the eq.-17 DLA.
# Called as gnuplot -e "file='results/geometry.json'; out='plots/geometry_extrinsic.png'" plots/geometry_extrinsic.gp
load "plots/style.gp"
set terminal pngcairo size 1500,600 enhanced font "DejaVu Sans,11" linewidth 1.2
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
# Intrinsic and omega-DLA: the DLA's style; extrinsic and eq.-17 DLA: dark dashed.
DLA = method_ls("dla a=0.5")
ALT = 'lc rgb "#003D66" dt (14,7) lw 1.5'
set multiplot title "Extrinsic (unit vectors, eq. 17) against intrinsic (angles) DLA, midpoint"
set key Left reverse font ",10" samplen 3.5 nobox noopaque
eval side(1, 3, 0.84, 0.27)
set title "robot, h = 0.2"
set xlabel "t".U
set ylabel "E − E_0".U
set xrange [0:30]
set key at screen 0.075, 0.14 left top
plot $robot_intrinsic u 1:2 ls DLA t "intrinsic (angles)", \
     $robot_extrinsic u 1:2 @ALT t "extrinsic (unit vectors)"
eval side(2, 3, 0.84, 0.27)
set title "robot: error of q(T = 2) against the exact reduced flow"
set xlabel "h".U
set ylabel "max-norm error of q(T = 2)".U
set xrange [*:*]
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set key at screen 0.395, 0.14 left top
plot $conv_intrinsic u 1:2 w lp ls DLA pt 7 t sprintf("intrinsic, order %.2f", oi), \
     $conv_extrinsic u 1:2 w lp @ALT pt 5 t sprintf("extrinsic, order %.2f", oe)
unset logscale
set format x "%g"
set format y "%g"
eval side(3, 3, 0.84, 0.27)
set title "circle (Remark 3.3), h = 0.1"
set xlabel "t".U
set ylabel "E − E_0".U
set xrange [0:100]
set key at screen 0.715, 0.14 left top
plot $circle_omega u 1:2 ls DLA lw 3 t "DLA with {/Symbol w} = q^T", \
     $circle_g u 1:2 lc rgb "black" dt (14,7) lw 1.2 t "DLA with g = (|q|^2 − 1)/2 (eq. 17)"
unset multiplot
