# Shared look of every figure: one colour per method, everywhere.
set terminal pngcairo size 1000,700 enhanced font "DejaVu Sans,11" linewidth 1.2
set grid lc rgb "#dddddd"
set key top left box opaque
set style line 1 lc rgb "#1f77b4" lw 1.5   # DLA
set style line 2 lc rgb "#d62728" lw 1.5   # RK4
set style line 3 lc rgb "#2ca02c" lw 2.0   # benchmark (CVODE Adams)
# Columns from a result file: time and one diagnostic (jq filter after the file).
col(file, filter) = sprintf("< jq -r '[.t, (%s)] | transpose[] | @tsv' %s", filter, file)
# One fixed colour and point type per method, everywhere: line style 10 + the
# method's "style" in the result JSON (its position in nhi::study_methods(),
# lib/nhi/methods.hpp).  Room for 12 methods.
set style line 11 lc rgb "#1f77b4" pt 7  lw 1.5   # dla a=0.5
set style line 12 lc rgb "#9467bd" pt 5  lw 1.5   # dla-sym a=0
set style line 13 lc rgb "#d62728" pt 9  lw 1.5   # rk4
set style line 14 lc rgb "#2ca02c" pt 13 lw 1.5   # reference (CVODE Adams)
set style line 15 lc rgb "#8c564b" pt 4  lw 1.5   # dla a=0
set style line 16 lc rgb "#e377c2" pt 6  lw 1.5   # dla a=0.25
set style line 17 lc rgb "#bcbd22" pt 8  lw 1.5   # dla a=0.75
set style line 18 lc rgb "#17becf" pt 10 lw 1.5   # dla a=1
set style line 19 lc rgb "#ff7f0e" pt 12 lw 1.5   # dla-sym a=0.25
set style line 20 lc rgb "#7f7f7f" pt 1  lw 1.5   # rkf78 (Boost.Odeint)
set style line 21 lc rgb "#000000" pt 2  lw 1.5   # dopri5 (Boost.Odeint)
set style line 22 lc rgb "#aec7e8" pt 3  lw 1.5   # (next method)
