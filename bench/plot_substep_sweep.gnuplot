# Substep sweep: final-position error (max over particles, relative to the cloth size) against substeps per
# 1/60 s step, log-log, one line per integrator, one panel per simulated time T.
# Usage: gnuplot -e "csv='FILE.csv'; durations='0.25 0.5'; png='OUT.png'" bench/plot_substep_sweep.gnuplot
#        (optional: integrators='verlet rk4')
set datafile separator ','
if (!exists("integrators")) integrators = "verlet symplectic-euler rk4 implicit-euler xpbd"
panels = words(durations)
set terminal pngcairo size 760 * panels, 600 enhanced font ',11'
set output png
set logscale x 2
set logscale y
set format x '%.0f'
set format y '10^{%L}'
set xtics 1, 4
set grid
set key bottom left
set xlabel 'substeps per 1/60 s step'
set ylabel 'max |x - x_{ref}| / cloth size at T'
# Columns: T,simulated_seconds,integrator,substeps,steps,substep,finite,stable,wall_seconds,error_max,...
series(T, i) = sprintf("< awk -F, '$1==\"%s\" && $3==\"%s\" && $8==1' %s", T, i, csv)
set multiplot layout 1, panels title 'clothsim: error against substeps (hanging 32 x 32, no ground; unstable runs left out)' noenhanced
do for [k = 1:panels] {
    T = word(durations, k)
    set title sprintf('T = %s s', T) noenhanced
    plot for [i in integrators] series(T, i) using 4:10 with linespoints lw 2 title i noenhanced
}
unset multiplot
