# Study 2: running maxima of |E - E0| and of the constraint value against t,
# log-log, so that bounded oscillation (flat) and drift (slope 1) separate.
# Called as gnuplot -e "file='results/long_horizon.json'; scene='particle'; out='plots/long_horizon_particle.png'" plots/long_horizon.gp
load "plots/style.gp"
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   N; LABEL, GROUP, STY[i + 1] of method i (label: fate, group, method_ls(label));
#   H (as text: the title prints it as is), T; RS, the reference solution's
#   steps (config.reference_steps; 10^6 where the file does not record it);
#   FI, the names of the first integrals besides E (the contact oscillators:
#   H_y, R), from method 0;
#   $E<i>, $C<i>: t and max |E - E0|, max constraint of method i if in the
#   "main" group, $V<i>: t and max |E - E0| if in the "variant" group;
#   $F<i>_<k>: t and max |I - I0| of the k-th name of FI if in "main".
# Rows where the value is not > 0 are dropped (log scale).  A method's blocks
# of the other group are empty: gnuplot skips them ("no valid points").
load jq_script(sprintf("--arg scene '%s'", scene), \
  '.scenes[$scene] as $s | ($s.methods[0].first_integrals // {} | keys) as $fi ' . \
  '| "N = \($s.methods | length)", "array LABEL[N]", "array GROUP[N]", "array STY[N]", ' . \
  '"H = \($s.h | gp)", "T = real(\($s.T | gp))", "RS = real(\(.config.reference_steps // 1000000 | gp))", "FI = \($fi | join(" ") | gp)", ' . \
  '($s.methods | to_entries[] | .key as $i | .value ' . \
  ' | "LABEL[\($i + 1)] = \("\(.label): \(.fate)" | gp)", "GROUP[\($i + 1)] = \(.group | gp)", ' . \
  '   "STY[\($i + 1)] = method_ls(\(.label | gp))", ' . \
  '   jq_block("$E\($i)"; select(.group == "main") | [.t, .max_energy_error] | transpose[] | select(.[1] > 0)), ' . \
  '   jq_block("$C\($i)"; select(.group == "main") | [.t, .max_constraint] | transpose[] | select(.[1] > 0)), ' . \
  '   jq_block("$V\($i)"; select(.group == "variant") | [.t, .max_energy_error] | transpose[] | select(.[1] > 0)), ' . \
  '   (($fi | to_entries[]) as $w | jq_block("$F\($i)_\($w.key + 1)"; ' . \
  '      select(.group == "main") | [.t, .first_integrals[$w.value].max_abs_error] | transpose[] | select(.[1] > 0)))), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
label(i) = LABEL[i + 1]
group(i) = GROUP[i + 1]
sty(i) = STY[i + 1]
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,800 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "t"
set key outside below font ",8" spacing 0.9 maxrows 6
set xrange [H:1.5*T]
set style data lines
if (strlen(FI) > 0) { set terminal pngcairo size 1500,1300 enhanced font "DejaVu Sans,10" linewidth 1.2; set output out }
set multiplot layout (strlen(FI) > 0 ? 2 : 1),3 title sprintf("Long horizon, h = %s, 10^6 steps, T = %.4g (%s; the reference solution: %.0e steps)", H, T, scene, RS) noenhanced
set title "max_{s <= t} |E - E_0|"
set yrange [1e-17:1e3]
plot for [i=0:N-1] sprintf("$E%d", i) u 1:2 ls sty(i) t (group(i) eq "main" ? label(i) : "")
set title "max_{s <= t} max_a |{/Symbol w}_a(q) v|"
set yrange [1e-17:1e3]
plot for [i=0:N-1] sprintf("$C%d", i) u 1:2 ls sty(i) t (group(i) eq "main" ? label(i) : "")
set title "variants (other alphas, more compositions): max_{s <= t} |E - E_0|"
set yrange [1e-12:1e6]
set format y "10^{%L}"
plot for [i=0:N-1] sprintf("$V%d", i) u 1:2 ls sty(i) t (group(i) eq "variant" ? label(i) : "")
if (strlen(FI) > 0) {
  set yrange [1e-17:1e3]
  do for [k=1:words(FI)] {
    w = word(FI, k)
    set title sprintf("main methods: max_{s <= t} |%s - %s_0|", w, w) noenhanced
    plot for [i=0:N-1] sprintf("$F%d_%d", i, k) u 1:2 ls sty(i) t (group(i) eq "main" ? label(i) : "")
  }
}
unset multiplot
