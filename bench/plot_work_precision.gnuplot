# Work-precision diagram of one scene: final-position error (max over particles, relative to the cloth
# size) against wall time per simulated second, log-log, one line per integrator.
# Usage: gnuplot -e "csv='FILE.csv'; scene='smooth'; png='OUT.png'" bench/plot_work_precision.gnuplot
set datafile separator ','
set terminal pngcairo size 900,600 enhanced font ',11'
set output png
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid
set key outside right
set xlabel 'wall time per simulated second (s)'
set ylabel 'max |x - x_{ref}| / cloth size at T'
set title sprintf('clothsim work-precision: %s', scene) noenhanced
# Columns: scene,integrator,substep,steps,finite,wall_seconds,seconds_per_simulated_second,error_max,...
series(i) = sprintf("< awk -F, '$1==\"%s\" && $2==\"%s\" && $5==1' %s", scene, i, csv)
plot for [i in "verlet symplectic-euler rk4 implicit-euler xpbd"] series(i) using 7:8 with linespoints lw 2 title i
