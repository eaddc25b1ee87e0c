# Stiff work-precision diagram of one grid size (clothsim-bench stiff-precision): max particle error over the
# cloth size at T = 0.25 s, 0.5 s and 1 s against wall time per simulated second (one thread), log-log, one
# line per integrator; the dashed line is the round-off floor (gravity one float ulp smaller).
# Usage: gnuplot -e "csv='FILE.csv'; size='64'; png='OUT.png'" bench/plot_stiff_precision.gnuplot
set datafile separator ','
set terminal pngcairo size 1500,520 enhanced font ',11'
set output png
set multiplot layout 1,3 title sprintf('clothsim stiff-hanging, %s x %s, cotton at its measured stretch: error against wall time (1 thread)', size, size) noenhanced
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid
set yrange [1e-7:3]
set xlabel 'wall s per simulated s'
set ylabel 'max |x - x_{ref}| / cloth size'
# Columns: size,integrator,substeps,stable_substeps,substep_over_critical,status,repeats,wall,cpu,predicted,
#          error_max_0.25,error_max_0.5,error_max_1,error_rms_0.25,error_rms_0.5,error_rms_1,floor_0.25,floor_0.5,floor_1,...
series(i) = sprintf("< awk -F, '$1==%s && $2==\"%s\" && $6==\"ok\"' %s", size, i, csv)
floor_line = sprintf("< awk -F, '$1==%s && $6==\"ok\"' %s", size, csv)
do for [k=0:2] {
    set title sprintf('T = %s s', word("0.25 0.5 1", k+1))
    if (k == 2) { set key outside right } else { unset key }
    plot for [i in "verlet symplectic-euler rk4 implicit-euler xpbd"] series(i) using 8:(column(11+k)) with linespoints lw 2 title i, \
         floor_line using 8:(column(17+k)) with lines dt 2 lc rgb 'black' title 'round-off floor'
}
unset multiplot
