# Measured largest stable substep against the predicted critical substep (Gershgorin bound), log-log.
# Usage: gnuplot -e "csv='FILE.csv'; png='OUT.png'" bench/plot_stability.gnuplot
set datafile separator ','
set terminal pngcairo size 900,650 enhanced font ',11'
set output png
set logscale xy
set format x '10^{%L}'
set format y '10^{%L}'
set grid
set key top left
set xlabel 'predicted critical substep (s), Gershgorin bound'
set ylabel 'measured largest stable substep (s)'
set title 'clothsim stability: measured against predicted (above the solid line: the prediction is safe)'
series(i) = sprintf("< awk -F, '$2==\"%s\"' %s", i, csv)
plot [1e-6:1] x with lines lc 'black' lw 1 title 'measured = predicted', \
     x * 2 with lines dt 2 lc 'gray' title 'measured = 2 x predicted', \
     series('symplectic-euler') using 7:9 with points pt 7 ps 1.0 title 'symplectic-euler', \
     series('rk4') using 7:9 with points pt 5 ps 1.0 title 'rk4', \
     series('verlet') using 7:9 with points pt 6 ps 2.0 lw 2 title 'verlet (same limit as symplectic Euler)'
