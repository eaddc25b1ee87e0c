# Time per substep against particle count (log-log), one line per solver and thread count, from the CSV
# written by clothsim-bench. Usage: gnuplot -e "csv='FILE.csv'; png='OUT.png'" bench/plot_throughput.gnuplot
set datafile separator ','
set terminal pngcairo size 900,600 enhanced font ',11'
set output png
set logscale xy
set format y '10^{%L}'
set format x '10^{%L}'
set grid
set key top left
set xlabel 'particles (grid side squared)'
set ylabel 'time per substep (s)'
set title 'clothsim: time per substep, hanging cloth (dashed: linear in particle count)'
# Columns: size,particles,springs,method,threads,ns_per_particle_step,... ; one series per method/threads.
series(m, t) = sprintf("< awk -F, '$4==\"%s\" && $5==%d' %s", m, t, csv)
plot series('textbook-aos', 1) using 2:($6 * $2 * 1e-9) with linespoints lw 2 title 'textbook, array of structs', \
     series('textbook', 1) using 2:($6 * $2 * 1e-9) with linespoints lw 2 title 'textbook, structure of arrays', \
     series('fast', 1) using 2:($6 * $2 * 1e-9) with linespoints lw 2 title 'fast, 1 thread', \
     series('fast', 2) using 2:($6 * $2 * 1e-9) with linespoints lw 2 title 'fast, 2 threads', \
     [1000:300000] 3.0e-9 * x with lines dt 2 lc 'gray' title '3 ns per particle (linear)'
