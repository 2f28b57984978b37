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
eval SORT_BY_STY  # ORD: the methods by family, reference first
label(i) = LABEL[i]
group(i) = GROUP[i]
sty(i) = STY[i]
# Lines, then their markers every EV points (staggered per method, so that
# markers of overlapping lines do not hide each other), drawn in the order ORD;
# the legends come from keyentry lines, one per method of the group shown.
EV = 26
set key noenhanced  # method labels contain underscores
fi = strlen(FI) > 0
set terminal pngcairo size 1500,(fi ? 1300 : 820) enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xlabel "t".U
set xrange [H:1.5*T]
set yrange [1e-17:1e3]
unset key
# Panel p (1-based, three a row) at its place; the legends go below all panels.
bot = fi ? 0.26 : 0.36
row_h = fi ? 0.28 : 0.52
panel(p) = sprintf("set lmargin at screen %g; set rmargin at screen %g; set tmargin at screen %g; set bmargin at screen %g", \
  0.065 + ((p - 1) % 3) * 0.33, 0.065 + ((p - 1) % 3) * 0.33 + 0.255, \
  bot + (fi ? 1 - int((p - 1) / 3) : 0) * (row_h + 0.085) + row_h, bot + (fi ? 1 - int((p - 1) / 3) : 0) * (row_h + 0.085))
set multiplot title sprintf("Long horizon, h = %s, 10^6 steps, T = %.4g (%s; the reference solution: %.0e steps)", H, T, scene, RS) noenhanced
eval panel(1)
set title "main methods: energy"
set ylabel "max_{s ≤ t} |E − E_0|".U
set key at screen 0.02, bot - 0.09 left top vertical maxrows 14 Left reverse font ",9" samplen 3.5 nobox noopaque
plot for [k=1:N] sprintf("$E%d", ORD[k] - 1) u 1:2 w l ls sty(ORD[k]) notitle, \
     for [k=1:N] sprintf("$E%d", ORD[k] - 1) every EV::(3 * k % EV) u 1:2 w p ls sty(ORD[k]) notitle, \
     for [k=1:N] keyentry w lp ls sty(ORD[k]) t (group(ORD[k]) eq "main" ? label(ORD[k]) : "")
unset key
eval panel(2)
set title "main methods: constraint"
set ylabel "max_{s ≤ t} max_a |{/Symbol w}_a(q) v|".U
plot for [k=1:N] sprintf("$C%d", ORD[k] - 1) u 1:2 w l ls sty(ORD[k]), \
     for [k=1:N] sprintf("$C%d", ORD[k] - 1) every EV::(3 * k % EV) u 1:2 w p ls sty(ORD[k])
eval panel(3)
set title "variants (other {/Symbol a}, compositions): energy"
set ylabel "max_{s ≤ t} |E − E_0|".U
set yrange [1e-12:1e6]
set key at screen 0.52, bot - 0.09 left top vertical maxrows 14 Left reverse font ",9" samplen 3.5 nobox noopaque
plot for [k=1:N] sprintf("$V%d", ORD[k] - 1) u 1:2 w l ls sty(ORD[k]) notitle, \
     for [k=1:N] sprintf("$V%d", ORD[k] - 1) every EV::(3 * k % EV) u 1:2 w p ls sty(ORD[k]) notitle, \
     for [k=1:N] keyentry w lp ls sty(ORD[k]) t (group(ORD[k]) eq "variant" ? label(ORD[k]) : "")
unset key
if (fi) {
  set yrange [1e-17:1e3]
  do for [j=1:words(FI)] {
    w = word(FI, j)
    eval panel(3 + j)
    set title sprintf("main methods: %s", w) noenhanced
    set ylabel sprintf("max_{s ≤ t} |%s − {%s}_0|", w, w).U
    plot for [k=1:N] sprintf("$F%d_%d", ORD[k] - 1, j) u 1:2 w l ls sty(ORD[k]), \
         for [k=1:N] sprintf("$F%d_%d", ORD[k] - 1, j) every EV::(3 * k % EV) u 1:2 w p ls sty(ORD[k])
  }
}
unset multiplot
