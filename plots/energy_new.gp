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
set output out
set multiplot layout 2,1 title label.", energy E - E_0 (h = 0.2), methods after the paper"
set xlabel "t"
set ylabel "E - E_0"
set key bottom left
plot $dla u 1:2 w l ls method_ls("dla a=0.5") t "DLA, {/Symbol a} = 1/2", \
     $mp u 1:2 w l ls method_ls("mp06") t "mp06", \
     $mptj u 1:2 w l ls method_ls("mp06+triple_jump") t "mp06, triple jump (order 4)", \
     $rk4 u 1:2 w l ls method_ls("rk4") t "RK4", \
     $ref u 1:2 w l ls method_ls("reference") t "reference (CVODE Adams, tol 1e-12)"
set xrange [0:40]
set title "first 40 time units"
set key bottom right horizontal maxrows 2
replot
unset multiplot
