# Shared look of every figure: one colour per method, everywhere.
set terminal pngcairo size 1000,700 enhanced font "DejaVu Sans,11" linewidth 1.2
set grid lc rgb "#dddddd"
set key top left box opaque
set style line 1 lc rgb "#1f77b4" lw 1.5   # DLA
set style line 2 lc rgb "#d62728" lw 1.5   # RK4
set style line 3 lc rgb "#2ca02c" lw 2.0   # benchmark (CVODE Adams)
# Columns from a result file: time and one diagnostic (jq filter after the file).
col(file, filter) = sprintf("< jq -r '[.t, (%s)] | transpose[] | @tsv' %s", filter, file)
