# Shared look of every figure: one hue per method family, everywhere.
set terminal pngcairo size 1000,700 enhanced font "DejaVu Sans,11" linewidth 1.2
set grid lc rgb "#dddddd"
set key top left box opaque
# Every scene is nondimensional: the axis labels say so (U, appended).
U = " (dimensionless)"
# Palette: Okabe & Ito's colour-blind-safe colours, one hue per method family
#   reference (CVODE)   black    #000000
#   DLA (the paper's)   blue     #0072B2  (other alphas: dark #003D66)
#   mp06 (RATTLE-type)  vermil.  #D55E00
#   discrete gradient   green    #009E73  (endpoint form: dark #005A42)
#   SPARK               orange   #E69F00
#   RK4                 purple   #CC79A7
#   adaptive rkf78/dopri5 sky    #56B4E9
# Members of a family differ by marker and dash: the base method solid with a
# filled circle, +triple_jump dashed with a triangle, +suzuki5 dash-dot with a
# diamond, +order6 dotted with a square; open markers for the variants (other
# alphas, the endpoint discrete gradient).  Marker types 1-3 (+, x, *) are
# left free: plots/stability.gp marks failed runs with them.
DASH = "(14,7)"
DOT = "(3,4)"
DASHDOT = "(14,5,3,5)"
LONG = "(30,8)"
# One fixed style per method, everywhere, keyed by the method's label
# (nhi::StudyMethod::label(), `nhi list`): method_ls(label) is its line style,
# the number its study entry declares (plots/method_styles.gp).
# Styles are numbered by family (reference 10, DLA 11-19, mp06 21-24, discrete
# gradient 31-38, SPARK 41-43, RK4 51, adaptive 61-62, the convergence study's
# isolation runs 71-78), so that sorting by style (SORT_BY_STY) groups a legend
# by family with the reference first.  A new method declares a number in its
# family's range; a label without one is drawn in grey (line style 99).
set style line 10 lc rgb "#000000" lw 2.0 dt 1 pt 7  ps 0.6
set style line 11 lc rgb "#0072B2" lw 1.5 dt 1 pt 7  ps 0.8
set style line 12 lc rgb "#0072B2" lw 1.5 dt @DASH pt 9  ps 0.9
set style line 13 lc rgb "#0072B2" lw 1.5 dt @DASHDOT pt 5  ps 0.8
set style line 14 lc rgb "#0072B2" lw 1.5 dt @DOT pt 11 ps 0.9
set style line 15 lc rgb "#003D66" lw 1.5 dt 1 pt 6  ps 0.8
set style line 16 lc rgb "#003D66" lw 1.5 dt @DASH pt 8  ps 0.9
set style line 17 lc rgb "#003D66" lw 1.5 dt @DOT pt 12 ps 0.9
set style line 18 lc rgb "#003D66" lw 1.5 dt @LONG pt 10 ps 0.9
set style line 19 lc rgb "#003D66" lw 1.5 dt @DASHDOT pt 4  ps 0.8
set style line 21 lc rgb "#D55E00" lw 1.5 dt 1 pt 7  ps 0.8
set style line 22 lc rgb "#D55E00" lw 1.5 dt @DASH pt 9  ps 0.9
set style line 23 lc rgb "#D55E00" lw 1.5 dt @DASHDOT pt 13 ps 0.9
set style line 24 lc rgb "#D55E00" lw 1.5 dt @DOT pt 5  ps 0.8
set style line 31 lc rgb "#009E73" lw 1.5 dt 1 pt 7  ps 0.8
set style line 32 lc rgb "#009E73" lw 1.5 dt @DASH pt 9  ps 0.9
set style line 33 lc rgb "#009E73" lw 1.5 dt @DASHDOT pt 13 ps 0.9
set style line 34 lc rgb "#009E73" lw 1.5 dt @DOT pt 5  ps 0.8
set style line 35 lc rgb "#005A42" lw 1.5 dt 1 pt 6  ps 0.8
set style line 36 lc rgb "#005A42" lw 1.5 dt @DASH pt 8  ps 0.9
set style line 37 lc rgb "#005A42" lw 1.5 dt @DASHDOT pt 12 ps 0.9
set style line 38 lc rgb "#005A42" lw 1.5 dt @DOT pt 4  ps 0.8
set style line 41 lc rgb "#E69F00" lw 1.5 dt 1 pt 7  ps 0.8
set style line 42 lc rgb "#E69F00" lw 1.5 dt @DASH pt 9  ps 0.9
set style line 43 lc rgb "#E69F00" lw 1.5 dt @DASHDOT pt 13 ps 0.9
set style line 51 lc rgb "#CC79A7" lw 1.5 dt 1 pt 11 ps 0.9
set style line 61 lc rgb "#56B4E9" lw 1.5 dt 1 pt 15 ps 0.9
set style line 62 lc rgb "#56B4E9" lw 1.5 dt @DASH pt 14 ps 0.9
# The convergence study's isolation runs (all DLA): a = 0 dark, a = 0.25 blue.
set style line 71 lc rgb "#003D66" lw 1.5 dt 1 pt 7  ps 0.8
set style line 72 lc rgb "#003D66" lw 1.5 dt @DASH pt 9  ps 0.9
set style line 73 lc rgb "#003D66" lw 1.5 dt @DASHDOT pt 13 ps 0.9
set style line 74 lc rgb "#003D66" lw 1.5 dt @DOT pt 5  ps 0.8
set style line 75 lc rgb "#0072B2" lw 1.5 dt 1 pt 6  ps 0.8
set style line 76 lc rgb "#0072B2" lw 1.5 dt @DASH pt 8  ps 0.9
set style line 77 lc rgb "#0072B2" lw 1.5 dt @DASHDOT pt 12 ps 0.9
set style line 78 lc rgb "#0072B2" lw 1.5 dt @DOT pt 4  ps 0.8
set style line 81 lc rgb "#882255" lw 1.5 dt 1 pt 13 ps 0.9
set style line 85 lc rgb "#882255" lw 1.5 dt @DASH pt 11 ps 0.9
set style line 99 lc rgb "#999999" lw 1.0 dt 1 pt 6  ps 0.8
# The methods' styles by label (method_ls), written from their declarations by
# `nhi list --gnuplot`; other_ls: the convergence study's isolation runs, else grey.
other_ls(label) = \
  label eq "L_d^a + omega_d^1/2, p0 = dL/dv (a=0)" ? 71 : \
  label eq "L_d^a + omega_d^1/2, consistent p0 (a=0)" ? 72 : \
  label eq "L_d^1/2 + omega_d^a, p0 = dL/dv (a=0)" ? 73 : \
  label eq "L_d^a + omega_d^a, consistent p0 (a=0)" ? 74 : \
  label eq "L_d^a + omega_d^1/2, p0 = dL/dv (a=0.25)" ? 75 : \
  label eq "L_d^a + omega_d^1/2, consistent p0 (a=0.25)" ? 76 : \
  label eq "L_d^1/2 + omega_d^a, p0 = dL/dv (a=0.25)" ? 77 : \
  label eq "L_d^a + omega_d^a, consistent p0 (a=0.25)" ? 78 : \
  99
load "plots/method_styles.gp"
# `eval SORT_BY_STY` after a script has set N and STY[1..N] (method_ls of each
# method): ORD[1..N] lists the methods' indices (1-based) by style, i.e. by
# family with the reference first.  Plot `for [k=1:N]` with ORD[k] to draw the
# reference first and group the legend by family.
SORT_BY_STY = "array ORD[N]; k_ = 0; do for [s_=1:99] { do for [i_=1:N] { if (STY[i_] == s_) { k_ = k_ + 1; ORD[k_] = i_ } } }"
# One jq pass per figure: calling jq once per label and per data series would
# start jq and parse the result hundreds of times a figure.  A script
# `load`s jq_script(opts, prog, files): the gnuplot commands that ONE run of
# `jq -r opts prog files` prints, i.e. assignments of the labels, styles and
# numbers, and every series as a datablock (jq_block) holding its rows as
# @tsv text.
# prog is written in gnuplot single quotes and goes to the shell in single
# quotes: it must not contain a ' (nor may opts and files need quoting).  Its
# last output must be "jq_ok = 1": jq stops at its first error (the message
# goes to stderr) and a shell without jq prints nothing, so every script checks
# exists("jq_ok") right after the load and exits with an error, before
# `set output` creates the PNG, instead of drawing an empty figure.
# Defined for prog:
#   gp     the gnuplot string literal of this value as system("jq -r ...")
#          would return it (a string raw, any other value as JSON); the
#          scripts convert numbers with int()/real().
#   jq_block($name; rows)   datablock $name, one @tsv line per row.  It is
#          empty where rows is: gnuplot then skips it with a
#          "no valid points" warning, and no key entry.
JQ_DEFS = 'def gp: (if type == "string" then . else tojson end) | tojson; ' . \
          'def jq_block($name; rows): "\($name) << EOD", (rows | @tsv), "EOD"; '
jq_script(opts, prog, files) = sprintf("< jq -r %s '%s%s' %s", opts, JQ_DEFS, prog, files)
# `eval stack(p, n, top, bot, gap)`: the margins of panel p (1 = top) of n
# panels stacked between screen heights top and bot, gap apart (room for the
# x label and the next title); a figure's legend goes above top, outside.
stack_h(n, top, bot, gap) = (top - bot - (n - 1) * gap) / n
stack(p, n, top, bot, gap) = sprintf("set lmargin at screen 0.10; set rmargin at screen 0.97; set tmargin at screen %g; set bmargin at screen %g", \
  top - (p - 1) * (stack_h(n, top, bot, gap) + gap), top - (p - 1) * (stack_h(n, top, bot, gap) + gap) - stack_h(n, top, bot, gap))
# `eval side(p, n, top, bot)`: the margins of panel p (1 = left) of n side by
# side between screen heights top and bot; legends go below bot, outside.
side(p, n, top, bot) = sprintf("set lmargin at screen %g; set rmargin at screen %g; set tmargin at screen %g; set bmargin at screen %g", \
  0.075 + (p - 1) * 0.96 / n, 0.005 + p * 0.96 / n, top, bot)
# plain(s): s with its underscores escaped, to print as is in enhanced text.
plain(s) = strstrt(s, "_") ? s[1:strstrt(s, "_") - 1] . "\\_" . plain(s[strstrt(s, "_") + 1:]) : s
