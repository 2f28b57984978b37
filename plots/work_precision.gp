# Study 4: CPU time against (a) the error at T = 10 and (b) the largest energy
# error over T = 10^4, every method on the same axes.
# Called as gnuplot -e "file='results/work_precision.json'; scene='particle'; out='plots/work_precision_particle.png'" plots/work_precision.gp
load "plots/style.gp"
set key noenhanced  # method labels contain underscores
set terminal pngcairo size 1400,600 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
set datafile separator "\t"
# The methods of this scene in their fixed order (style), from the JSON.
methods = sprintf("jq -r '[.scenes.%s.runs[] | {label: .label, style: .style}] | unique_by(.style) | .[]' %s", scene, file)
N = int(system(methods . " | jq -s length"))
lab_of(i) = system(methods . sprintf(" | jq -s -r '.[%d].label'", i - 1))
sty_of(i) = 10 + int(system(methods . sprintf(" | jq -s -r '.[%d].style'", i - 1)))
# Each method's label and style read once (two jq calls each), not per use.
array LAB[N]
array STY[N]
do for [j=1:N] { LAB[j] = lab_of(j); STY[j] = sty_of(j) }
lab(i) = LAB[i]
sty(i) = STY[i]
pts(i, err, cpu) = sprintf("< jq -r '.scenes.%s.runs[] | select(.label == \"%s\" and .status == \"ok\") | [.%s, .%s] | @tsv' %s", scene, lab(i), cpu, err, file)
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set key top right font ",9"
set style data linespoints
set multiplot layout 1,2 title sprintf("Work-precision (%s): fixed-step methods over h = 0.4/2^j, adaptive ones over tolerances 1e-3 ... 1e-13", scene) noenhanced
set title "error in q at T = 10 against CPU time"
set xlabel "CPU seconds per run"
set ylabel "max_i |q_i(T) - q_{ref,i}(T)|"
plot for [i=1:N] pts(i, "final_error", "cpu_final") u 1:2 ls sty(i) ps 0.9 t lab(i)
set title "largest |E - E_0| over T = 10^4 against CPU time"
set ylabel "max |E - E_0|"
plot for [i=1:N] pts(i, "max_energy_error", "cpu_energy") u 1:2 ls sty(i) ps 0.9 t lab(i)
unset multiplot
