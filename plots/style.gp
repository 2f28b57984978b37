# Shared look of every figure: one colour per method, everywhere.
set terminal pngcairo size 1000,700 enhanced font "DejaVu Sans,11" linewidth 1.2
set grid lc rgb "#dddddd"
set key top left box opaque
set style line 1 lc rgb "#1f77b4" lw 1.5   # DLA
set style line 2 lc rgb "#d62728" lw 1.5   # RK4
set style line 3 lc rgb "#2ca02c" lw 2.0   # benchmark (CVODE Adams)
# One fixed colour and point type per method, everywhere, keyed by the
# method's label (nhi::StudyMethod::label(), `nhi list`): method_ls(label) is
# its line style.  A new method gets a line of its own here and moves no other
# method's colour; a label not listed is drawn in grey (line style 40).
set style line 11 lc rgb "#1f77b4" pt 7  lw 1.5
set style line 12 lc rgb "#9467bd" pt 5  lw 1.5
set style line 13 lc rgb "#17becf" pt 15 lw 1.5
set style line 14 lc rgb "#d62728" pt 9  lw 1.5
set style line 15 lc rgb "#2ca02c" pt 13 lw 1.5
set style line 16 lc rgb "#ff7f0e" pt 11 lw 1.5
set style line 17 lc rgb "#e6550d" pt 14 lw 1.5
set style line 18 lc rgb "#fdae6b" pt 12 lw 1.5
set style line 19 lc rgb "#a63603" pt 3  lw 1.5
set style line 20 lc rgb "#8c564b" pt 6  lw 1.5
set style line 21 lc rgb "#5a3a1a" pt 8  lw 1.5
set style line 22 lc rgb "#c49c94" pt 4  lw 1.5
set style line 23 lc rgb "#e377c2" pt 6  lw 1.5
set style line 24 lc rgb "#bcbd22" pt 8  lw 1.5
set style line 25 lc rgb "#393b79" pt 10 lw 1.5
set style line 26 lc rgb "#ce6dbd" pt 12 lw 1.5
set style line 27 lc rgb "#6baed6" pt 1  lw 1.5
set style line 28 lc rgb "#d6a06b" pt 2  lw 1.5
set style line 29 lc rgb "#7b4173" pt 3  lw 1.5
set style line 30 lc rgb "#7f7f7f" pt 1  lw 1.5
set style line 31 lc rgb "#000000" pt 2  lw 1.5
set style line 32 lc rgb "#637939" pt 5  lw 1.5
set style line 33 lc rgb "#8ca252" pt 7  lw 1.5
set style line 34 lc rgb "#b5cf6b" pt 9  lw 1.5
set style line 35 lc rgb "#843c39" pt 4  lw 1.5
set style line 36 lc rgb "#ad494a" pt 6  lw 1.5
set style line 37 lc rgb "#d6616b" pt 8  lw 1.5
set style line 38 lc rgb "#e7969c" pt 10 lw 1.5
set style line 40 lc rgb "#aaaaaa" pt 1  lw 1.0
method_ls(label) = \
  label eq "dla a=0.5" ? 11 : \
  label eq "dla-sym a=0" ? 12 : \
  label eq "dla a=0.5+triple_jump" ? 13 : \
  label eq "rk4" ? 14 : \
  label eq "reference" ? 15 : \
  label eq "mp06" ? 16 : \
  label eq "mp06+triple_jump" ? 17 : \
  label eq "mp06+suzuki5" ? 18 : \
  label eq "mp06+order6" ? 19 : \
  label eq "discrete_gradient" ? 20 : \
  label eq "discrete_gradient+triple_jump" ? 21 : \
  label eq "dla a=0" ? 22 : \
  label eq "dla a=0.25" ? 23 : \
  label eq "dla a=0.75" ? 24 : \
  label eq "dla a=1" ? 25 : \
  label eq "dla-sym a=0.25" ? 26 : \
  label eq "dla-sym a=0+triple_jump" ? 27 : \
  label eq "discrete_gradient+suzuki5" ? 28 : \
  label eq "discrete_gradient+order6" ? 29 : \
  label eq "rkf78" ? 30 : \
  label eq "dopri5" ? 31 : \
  label eq "spark s=2" ? 32 : \
  label eq "spark s=3" ? 33 : \
  label eq "spark s=4" ? 34 : \
  label eq "discrete_gradient endpoint" ? 35 : \
  label eq "discrete_gradient endpoint+triple_jump" ? 36 : \
  label eq "discrete_gradient endpoint+suzuki5" ? 37 : \
  label eq "discrete_gradient endpoint+order6" ? 38 : \
  40
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
