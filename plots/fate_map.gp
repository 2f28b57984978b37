# The fate-map sweep (make sweep): for one scene, one panel per value of the
# swept parameter; per method (rows) and h (columns) the fraction of the
# initial states whose run stayed stable to T (colour), and the largest h up to
# which every run was stable (black square; none where even the smallest h fails).
# Called as gnuplot -e "file='results/fate_map.json'; scene='contact_oscillator'; out='plots/fate_map_contact_oscillator.png'" plots/fate_map.gp
load "plots/style.gp"
set terminal pngcairo size 1600,1000 enhanced font "DejaVu Sans,10" linewidth 1.2
set output out
V = int(system(sprintf("jq '.config.values | length' %s", file)))
M = int(system(sprintf("jq '.scenes.%s.by_value[0].methods | length' %s", scene, file)))
param = system(sprintf("jq -r '.config.param' %s", file))
states = int(system(sprintf("jq '.config.states' %s", file)))
T = system(sprintf("jq '.config.T' %s", file))
pval(e) = system(sprintf("jq '.config.values[%d]' %s", e, file))
label(m) = system(sprintf("jq -r '.scenes.%s.by_value[0].methods[%d].label' %s", scene, m, file))
# x = log10 h (a uniform grid), y = method index, z = stable fraction
grid(e) = sprintf("< jq -r '.config.h as $h | .scenes.%s.by_value[%d].methods | to_entries[] | .key as $m | .value.stable | to_entries[] | [($h[.key] | log10), $m, (.value / %d)] | @tsv' %s", scene, e, states, file)
edge(e) = sprintf("< jq -r '.scenes.%s.by_value[%d].methods | to_entries[] | select(.value.largest_h_all_stable != null) | [.key, (.value.largest_h_all_stable | log10)] | @tsv' %s", scene, e, file)
set datafile separator "\t"
set palette defined (0 "#b2182b", 0.5 "#f7f7f7", 1 "#2166ac")
unset key
set cbrange [0:1]
set cblabel "fraction of runs stable to T"
set yrange [-0.5:M-0.5]
set ytics () font ",8" noenhanced
do for [m=0:M-1] { set ytics add (label(m) m) }
hmin = system(sprintf("jq '.config.h[0] | log10' %s", file)) + 0
hmax = system(sprintf("jq '.config.h[-1] | log10' %s", file)) + 0
dh = (hmax - hmin) / (int(system(sprintf("jq '.config.h | length' %s", file))) - 1)
set xrange [hmin - dh/2 : hmax + dh/2]
set xlabel "h".U
set xtics ("0.05" log10(0.05), "0.1" -1, "0.2" log10(0.2), "0.5" log10(0.5), "1" 0, "2" log10(2), "5" log10(5))
set multiplot layout 2,(V+1)/2 title sprintf("Fate map of %s: %d initial states, T = %s, per method and h; black: largest h with every run stable", scene, states, T) noenhanced
do for [e=0:V-1] {
  set title sprintf("%s = %s", param, pval(e)) noenhanced
  plot grid(e) u 1:2:3 with image notitle, \
       edge(e) u 2:1 w p pt 5 ps 0.8 lc rgb "black" notitle
}
unset multiplot
