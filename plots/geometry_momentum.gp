# Theorem 5.3 (eq. 24) along DLA runs at h = 0.2: the discrete nonholonomic
# momentum J_k against J_0 + sum of the right-hand sides of eq. (24) (they must
# coincide), and the per-step residual |J_{k+1} - J_k - rhs_k|.
# Called as gnuplot -e "file='results/geometry.json'; out='plots/geometry_momentum.png'" plots/geometry_momentum.gp
load "plots/style.gp"
set terminal pngcairo size 1500,520 enhanced font "DejaVu Sans,10" linewidth 1.2
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
set xlabel "t"
set multiplot layout 1,3 title "Discrete nonholonomic momentum equation (Theorem 5.3, eq. 24), DLA, h = 0.2"
set title "particle, V = y^2: J = p_x + y p_z (DLA {/Symbol a} = 1/4 dissipates)"
set key bottom right font ",8"
plot run("particle", 0, "J") u 1:2 ls 1 lw 2.5 t "J_k, {/Symbol a} = 1/2", \
     run("particle", 0, "J0_plus_sum_rhs") u 1:2 lc rgb "black" dt 2 lw 1 t "J_0 + {/Symbol S} rhs (eq. 24), {/Symbol a} = 1/2", \
     run("particle", 1, "J") u 1:2 lc rgb "#ff7f0e" lw 2.5 t "J_k, {/Symbol a} = 1/4", \
     run("particle", 1, "J0_plus_sum_rhs") u 1:2 lc rgb "#555555" dt 3 lw 1 t "J_0 + {/Symbol S} rhs, {/Symbol a} = 1/4"
set title "robot, SE(2): J = p_{/Symbol q} (its rhs is round-off: J is conserved)"
set ylabel "J_k - J_0"
set format y "%.0te%T"
plot run("robot", 0, "J") u 1:($2 - J0r) ls 1 lw 2 t "J_k - J_0, {/Symbol a} = 1/2", \
     run("robot", 0, "J0_plus_sum_rhs") u 1:($2 - J0r) lc rgb "black" dt 2 lw 1 t "{/Symbol S} rhs (eq. 24), {/Symbol a} = 1/2"
unset ylabel
set format y "%g"
set format y "10^{%L}"
set title "per-step residual |J_{k+1} - J_k - rhs_k|"
set logscale y
set format y "10^{%L}"
set yrange [1e-19:1e-10]
set key top right font ",8"
plot res("particle", 0) u 1:2 w points pt 7 ps 0.2 lc rgb "#1f77b4" t "particle, {/Symbol a} = 1/2", \
     res("particle", 1) u 1:2 w points pt 7 ps 0.2 lc rgb "#ff7f0e" t "particle, {/Symbol a} = 1/4", \
     res("robot", 0) u 1:2 w points pt 7 ps 0.2 lc rgb "#2ca02c" t "robot, {/Symbol a} = 1/2"
unset multiplot
