# Theorem 5.3 (eq. 24) along DLA runs at h = 0.2: the discrete nonholonomic
# momentum J_k against J_0 + sum of the right-hand sides of eq. (24) (they must
# coincide), and the per-step residual |J_{k+1} - J_k - rhs_k|.
# Called as gnuplot -e "file='results/geometry.json'; out='plots/geometry_momentum.png'" plots/geometry_momentum.gp
load "plots/style.gp"
set terminal pngcairo size 1500,580 enhanced font "DejaVu Sans,11" linewidth 1.2
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   J0r, J_0 of the robot's run 0;
#   $<sys>_<i>_J, $<sys>_<i>_J0_plus_sum_rhs: t and J, t and J_0 + sum of the
#   rhs along run i of sys (particle, robot);
#   $<sys>_<i>_res: t_k and the residual of step k, where it is > 0 (log scale).
load jq_script("", \
  '.momentum | "J0r = real(\(.robot.runs[0].J[0] | gp))", ' . \
  '(to_entries[] | .key as $sys | .value.runs | to_entries[] | .key as $i | .value ' . \
  ' | (("J", "J0_plus_sum_rhs") as $key | jq_block("$\($sys)_\($i)_\($key)"; [.t, .[$key]] | transpose[])), ' . \
  '   jq_block("$\($sys)_\($i)_res"; [.t[:-1], .residual] | transpose[] | select(.[1] > 0))), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
run(sys, i, key) = sprintf("$%s_%d_%s", sys, i, key)
res(sys, i) = sprintf("$%s_%d_res", sys, i)
set output out
set style data lines
set xlabel "t".U
# J_k of the DLA (alpha = 1/2 in its blue, alpha = 1/4 in a light tint of it)
# under the thin black dashes of J_0 + sum rhs, which must coincide with it.
A2 = 'lc rgb "#0072B2"'
A4 = 'lc rgb "#7FB8D9"'
PRED = 'lc rgb "black" dt (14,7) lw 1'
set multiplot title "Discrete nonholonomic momentum equation (Theorem 5.3, eq. 24), DLA, h = 0.2"
set key Left reverse font ",10" samplen 3.5 nobox noopaque
eval side(1, 3, 0.84, 0.31)
set title "particle, V = y^2: J = p_x + y p_z (DLA {/Symbol a} = 1/4 dissipates)"
set ylabel "J".U
set key at screen 0.075, 0.185 left top
plot run("particle", 0, "J") u 1:2 @A2 lw 3 t "J_k, {/Symbol a} = 1/2", \
     run("particle", 1, "J") u 1:2 @A4 lw 3 t "J_k, {/Symbol a} = 1/4", \
     run("particle", 0, "J0_plus_sum_rhs") u 1:2 @PRED t "J_0 + {/Symbol S} rhs (eq. 24), each {/Symbol a}", \
     run("particle", 1, "J0_plus_sum_rhs") u 1:2 @PRED notitle
eval side(2, 3, 0.84, 0.31)
set title "robot, SE(2): J = p_{/Symbol q} (its rhs is round-off: J is conserved)"
set ylabel "J_k − J_0".U
set format y "%.0te%T"
set key at screen 0.395, 0.185 left top
plot run("robot", 0, "J") u 1:($2 - J0r) @A2 lw 2 t "J_k − J_0, {/Symbol a} = 1/2", \
     run("robot", 0, "J0_plus_sum_rhs") u 1:($2 - J0r) @PRED t "{/Symbol S} rhs (eq. 24), {/Symbol a} = 1/2"
eval side(3, 3, 0.84, 0.31)
set title "per-step residual |J_{k+1} − J_k − rhs_k|"
set ylabel "|J_{k+1} − J_k − rhs_k|".U
set logscale y
set format y "10^{%L}"
set yrange [1e-19:1e-10]
set key at screen 0.715, 0.185 left top
plot res("particle", 0) u 1:2 w points pt 7 ps 0.25 @A2 notitle, \
     res("particle", 1) u 1:2 w points pt 7 ps 0.25 @A4 notitle, \
     res("robot", 0) u 1:2 w points pt 7 ps 0.25 lc rgb "#555555" notitle, \
     keyentry w p pt 7 ps 1 @A2 t "particle, {/Symbol a} = 1/2", \
     keyentry w p pt 7 ps 1 @A4 t "particle, {/Symbol a} = 1/4", \
     keyentry w p pt 7 ps 1 lc rgb "#555555" t "robot, {/Symbol a} = 1/2"
unset multiplot
