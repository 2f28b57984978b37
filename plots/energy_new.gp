# Companion to Figures 1 and 3: energy along the paper's DLA
# (alpha = 1/2), McLachlan & Perlmutter's mp06 and its triple-jump composition
# (order 4), RK4 and the reference solution, h = 0.2.  Called as plots/energy.gp
# (stem, out, label), reading stem_{dla,mp06,mp06tj,rk4,benchmark}.json.  Line
# styles are the methods' fixed styles of plots/style.gp.
load "plots/style.gp"
dla = stem."_dla.json"
mp = stem."_mp06.json"
mptj = stem."_mp06tj.json"
rk4 = stem."_rk4.json"
ref = stem."_benchmark.json"
# $ref, $dla, $mp, $mptj, $rk4: t and E - E_0 of each run, E_0 the reference's
# first energy, from one jq pass over the five files, ref first (jq_script,
# plots/style.gp; it also spares the replot a second pass).
load jq_script("-n", \
  'input as $ref | $ref.energy[0] as $E0 | def e: [.t, (.energy | map(. - $E0))] | transpose[]; ' . \
  'jq_block("$ref"; $ref | e), (("dla", "mp", "mptj", "rk4") as $name | input | jq_block("$\($name)"; e)), ' . \
  '"jq_ok = 1"', sprintf("%s %s %s %s %s", ref, dla, mp, mptj, rk4))
if (!exists("jq_ok")) { exit error sprintf("%s: jq failed on %s_*.json, no figure drawn", out, stem) }
set terminal pngcairo size 1000,780 enhanced font "DejaVu Sans,11" linewidth 1.2
set output out
set multiplot title label.", energy E − E_0 (h = 0.2), methods after the paper"
set xlabel "t".U
set ylabel "E − E_0".U
# One legend for both panels, above them (never on the data); the reference first.
set key at screen 0.5, 0.935 center top horizontal maxcols 3 Left reverse font ",10" samplen 3 width 2 nobox noopaque
P = '$ref u 1:2 w l ls method_ls("reference") t "reference (CVODE Adams, tol 1e-12)", ' . \
    '$dla u 1:2 w l ls method_ls("dla a=0.5") t "DLA, {/Symbol a} = 1/2", ' . \
    '$mp u 1:2 w l ls method_ls("mp06") t "mp06", ' . \
    '$mptj u 1:2 w l ls method_ls("mp06+triple_jump") t "mp06, triple jump (order 4)", ' . \
    '$rk4 u 1:2 w l ls method_ls("rk4") t "RK4"'
eval stack(1, 2, 0.81, 0.08, 0.15)
set title "whole run"
plot @P
unset key
eval stack(2, 2, 0.81, 0.08, 0.15)
set xrange [0:40]
set title "first 40 time units"
plot @P
unset multiplot
