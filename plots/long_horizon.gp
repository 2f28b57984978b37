# Study 2: running maxima of |E - E0| and of the constraint value against t,
# log-log, so that bounded oscillation (flat) and drift (slope 1) separate.
# Called as gnuplot -e "file='results/long_horizon.json'; scene='particle'; out='plots/long_horizon_particle.png'" plots/long_horizon.gp
load "plots/style.gp"
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,800 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
series(i, key, group) = sprintf("< jq -r '.scenes.%s.methods[%d] | select(.group == \"%s\") | [.t, .%s] | transpose[] | select(.[1] > 0) | @tsv' %s", scene, i, group, key, file)
label_of(i) = system(sprintf("jq -r '.scenes.%s.methods[%d] | \"\\(.label): \\(.fate)\"' %s", scene, i, file))
group_of(i) = system(sprintf("jq -r '.scenes.%s.methods[%d].group' %s", scene, i, file))
# Line style of method i: 10 + its fixed style (plots/style.gp).
sty_of(i) = 10 + int(system(sprintf("jq -r '.scenes.%s.methods[%d].style // 12' %s", scene, i, file)))
N = int(system(sprintf("jq '.scenes.%s.methods | length' %s", scene, file)))
# Each method's label, group and style read once (a jq call each), not once per panel.
array LABEL[N]
array GROUP[N]
array STY[N]
do for [j=1:N] { LABEL[j] = label_of(j - 1); GROUP[j] = group_of(j - 1); STY[j] = sty_of(j - 1) }
label(i) = LABEL[i + 1]
group(i) = GROUP[i + 1]
sty(i) = STY[i + 1]
H = system(sprintf("jq -r '.scenes.%s.h' %s", scene, file))
T = real(system(sprintf("jq -r '.scenes.%s.T' %s", scene, file)))
# Systems with first integrals besides E (the contact oscillators: H_y, R) get a fourth panel.
FI = system(sprintf("jq -r '.scenes.%s.methods[0].first_integrals // {} | keys | join(\" \")' %s", scene, file))
fiseries(i, name) = sprintf("< jq -r '.scenes.%s.methods[%d] | select(.group == \"main\") | [.t, .first_integrals.%s.max_abs_error] | transpose[] | select(.[1] > 0) | @tsv' %s", scene, i, name, file)
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "t"
set key outside below font ",8" spacing 0.9 maxrows 6
set xrange [H:1.5*T]
set style data lines
if (strlen(FI) > 0) { set terminal pngcairo size 1500,1300 enhanced font "DejaVu Sans,10" linewidth 1.2; set output out }
set multiplot layout (strlen(FI) > 0 ? 2 : 1),3 title sprintf("Long horizon, h = %s, 10^6 steps, T = %.4g (%s)", H, T, scene) noenhanced
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
if (strlen(FI) > 0) {
  set yrange [1e-17:1e3]
  do for [w in FI] {
    set title sprintf("main methods: max_{s <= t} |%s - %s_0|", w, w) noenhanced
    plot for [i=0:N-1] fiseries(i, w) u 1:2 ls sty(i) t (group(i) eq "main" ? label(i) : "")
  }
}
unset multiplot
