# Study 2: running maxima of |E - E0| and of the constraint value against t,
# log-log, so that bounded oscillation (flat) and drift (slope 1) separate.
# Called as gnuplot -e "file='results/long_horizon.json'; scene='particle'; out='plots/long_horizon_particle.png'" plots/long_horizon.gp
load "plots/style.gp"
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,800 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
series(i, key, group) = sprintf("< jq -r '.scenes.%s.methods[%d] | select(.group == \"%s\") | [.t, .%s] | transpose[] | select(.[1] > 0) | @tsv' %s", scene, i, group, key, file)
label(i) = system(sprintf("jq -r '.scenes.%s.methods[%d] | \"\\(.label): \\(.fate)\"' %s", scene, i, file))
group(i) = system(sprintf("jq -r '.scenes.%s.methods[%d].group' %s", scene, i, file))
# Line style of method i: 10 + its fixed style (plots/style.gp).
sty(i) = 10 + int(system(sprintf("jq -r '.scenes.%s.methods[%d].style // 12' %s", scene, i, file)))
N = int(system(sprintf("jq '.scenes.%s.methods | length' %s", scene, file)))
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "t"
set key outside below font ",8" spacing 0.9 maxrows 6
set xrange [0.2:3e5]
set style data lines
set multiplot layout 1,3 title sprintf("Long horizon, h = 0.2, T = 2x10^5 (%s)", scene)
set title "max_{s <= t} |E - E_0|"
set yrange [1e-17:1e3]
plot for [i=0:N-1] series(i, "max_energy_error", "main") u 1:2 ls sty(i) t (group(i) eq "main" ? label(i) : "")
set title "max_{s <= t} max_a |{/Symbol w}_a(q) v|"
set yrange [1e-17:1e3]
plot for [i=0:N-1] series(i, "max_constraint", "main") u 1:2 ls sty(i) t (group(i) eq "main" ? label(i) : "")
set title "variants (other alphas, more compositions): max_{s <= t} |E - E_0|"
set yrange [1e-12:1e6]
set format y "10^{%L}"
plot for [i=0:N-1] series(i, "max_energy_error", "variant") u 1:2 ls sty(i) t (group(i) eq "variant" ? label(i) : "")
unset multiplot
