# Companion to Figures 1 and 3 (issue 11): energy along the paper's DLA
# (alpha = 1/2), McLachlan & Perlmutter's mp06 and its triple-jump composition
# (order 4), RK4 and the reference solution, h = 0.2.  Called as plots/energy.gp
# (stem, out, label), reading stem_{dla,mp06,mp06tj,rk4,benchmark}.json.  Line
# styles are the methods' fixed styles of plots/style.gp.
load "plots/style.gp"
set output out
dla = stem."_dla.json"
mp = stem."_mp06.json"
mptj = stem."_mp06tj.json"
rk4 = stem."_rk4.json"
ref = stem."_benchmark.json"
set multiplot layout 2,1 title label.", energy E - E_0 (h = 0.2), methods after the paper"
set xlabel "t"
set ylabel "E - E_0"
set key bottom left
E0 = system(sprintf("jq '.energy[0]' %s", ref)) + 0
e(file) = col(file, sprintf(".energy | map(. - %.17g)", E0))
plot e(dla) u 1:2 w l ls 11 t "DLA, {/Symbol a} = 1/2", \
     e(mp) u 1:2 w l ls 16 t "mp06", \
     e(mptj) u 1:2 w l ls 17 t "mp06, triple jump (order 4)", \
     e(rk4) u 1:2 w l ls 14 t "RK4", \
     e(ref) u 1:2 w l ls 15 t "reference (CVODE Adams, tol 1e-12)"
set xrange [0:40]
set title "first 40 time units"
set key bottom right horizontal maxrows 2
replot
unset multiplot
