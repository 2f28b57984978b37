# Study 4: CPU time against (a) the error at T = 10 and (b) the largest energy
# error over T = 10^4, every method on the same axes.
# Called as gnuplot -e "file='results/work_precision.json'; scene='particle'; out='plots/work_precision_particle.png'" plots/work_precision.gp
load "plots/style.gp"
# Everything the figure needs, from one jq pass (jq_script, plots/style.gp):
#   N, the methods of this scene in the order of their first run;
#   LAB[i], STY[i] of the i-th (label, method_ls(label)), i = 1..N;
#   $FINAL<i>: CPU time and error at T = 10, $ENERGY<i>: CPU time and max
#   |E - E0| over T = 10^4, of the runs of the i-th method with status ok.
load jq_script(sprintf("--arg scene '%s'", scene), \
  '.scenes[$scene].runs as $runs | reduce ($runs[] | .label) as $l ([]; if index([$l]) then . else . + [$l] end) ' . \
  '| "N = \(length)", "array LAB[N]", "array STY[N]", ' . \
  '(to_entries[] | (.key + 1) as $i | .value as $lab ' . \
  ' | "LAB[\($i)] = \($lab | gp)", "STY[\($i)] = method_ls(\($lab | gp))", ' . \
  '   jq_block("$FINAL\($i)"; $runs[] | select(.label == $lab and .status == "ok") | [.cpu_final, .final_error]), ' . \
  '   jq_block("$ENERGY\($i)"; $runs[] | select(.label == $lab and .status == "ok") | [.cpu_energy, .max_energy_error])), ' . \
  '"jq_ok = 1"', file)
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s, no figure drawn", out, file) }
eval SORT_BY_STY  # ORD: the methods by family, reference first
lab(i) = LAB[i]
sty(i) = STY[i]
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1500,820 enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set datafile separator "\t"
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set style data linespoints
# Both panels over the top 75 %, one legend for both below them.
set multiplot title sprintf("Work-precision (%s): fixed-step methods over h = 0.4/2^j, adaptive ones over tolerances 1e-3 ... 1e-13", scene) noenhanced
set tmargin at screen 0.91
set bmargin at screen 0.24
set lmargin at screen 0.07
set rmargin at screen 0.48
set key at screen 0.07, 0.135 left top vertical maxrows 4 Left reverse font ",10" width 2 samplen 3.5 nobox noopaque
set title "error in q at T = 10 against CPU time"
set xlabel "CPU seconds per run"
set ylabel "max_i |q_i(T) − q_{ref,i}(T)|".U
plot for [k=1:N] sprintf("$FINAL%d", ORD[k]) u 1:2 ls sty(ORD[k]) t lab(ORD[k])
set lmargin at screen 0.57
set rmargin at screen 0.98
unset key
set title "largest |E − E_0| over T = 10^4 against CPU time"
set ylabel "max |E − E_0|".U
plot for [k=1:N] sprintf("$ENERGY%d", ORD[k]) u 1:2 ls sty(ORD[k])
unset multiplot
