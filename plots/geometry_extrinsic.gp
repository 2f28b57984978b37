# The Constrained Coordinate Formulation (eq. 17).  Robot: the intrinsic DLA
# (angles) against the extrinsic one (unit vectors, |u| = 1 as holonomic
# constraints), energy and convergence; circle (Remark 3.3): the omega-DLA and
# the eq.-17 DLA.
# Called as gnuplot -e "file='results/geometry.json'; out='plots/geometry_extrinsic.png'" plots/geometry_extrinsic.gp
load "plots/style.gp"
set terminal pngcairo size 1500,520 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
ser(path, key) = sprintf("< jq -r '%s | [.t, .%s] | transpose[] | @tsv' %s", path, key, file)
conv(key) = sprintf("< jq -r '.extrinsic.convergence | [.h, .%s] | transpose[] | @tsv' %s", key, file)
oi = real(system(sprintf("jq '.extrinsic.convergence.order_intrinsic' %s", file)))
oe = real(system(sprintf("jq '.extrinsic.convergence.order_extrinsic' %s", file)))
set style data lines
set multiplot layout 1,3 title "Extrinsic (unit vectors, eq. 17) against intrinsic (angles) DLA, midpoint"
set title "robot, h = 0.2: E - E_0"
set xlabel "t"
set xrange [0:30]
set key bottom right font ",8"
plot ser(".extrinsic.intrinsic", "energy_error") u 1:2 ls 1 t "intrinsic (angles)", \
     ser(".extrinsic.extrinsic", "energy_error") u 1:2 lc rgb "#ff7f0e" t "extrinsic (unit vectors)"
set title "robot: max-norm error of q(T = 2) against the exact reduced flow"
set xlabel "h"
set xrange [*:*]
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set key top left font ",8"
plot conv("intrinsic") u 1:2 w lp ls 1 pt 7 t sprintf("intrinsic, order %.2f", oi), \
     conv("extrinsic") u 1:2 w lp lc rgb "#ff7f0e" pt 5 t sprintf("extrinsic, order %.2f", oe)
unset logscale
set format x "%g"
set format y "%g"
set title "circle (Remark 3.3), h = 0.1: E - E_0"
set xlabel "t"
set xrange [0:100]
set key bottom right font ",8"
plot ser(".holonomic.circle.omega", "energy_error") u 1:2 ls 1 lw 2.5 t "DLA with {/Symbol w} = q^T", \
     ser(".holonomic.circle.g", "energy_error") u 1:2 lc rgb "black" dt 2 t "DLA with g = (|q|^2 - 1)/2 (eq. 17)"
unset multiplot
