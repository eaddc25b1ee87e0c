# clothsim-bench contention: for each path, size and load, the default's time over the faster of 1 and 2
# threads, and 2 threads forced over 1 thread forced (log scale), from the CSV of `clothsim-bench contention`.
# Usage: gnuplot -e "csv='FILE.csv'; png='OUT.png'" bench/plot_contention.gnuplot
set datafile separator ','
set terminal pngcairo size 1100,560 enhanced font ',10'
set output png
set logscale y
set yrange [0.4:*]
set grid ytics
set key top left
set ylabel 'time ratio (log)'
set xtics rotate by -60 font ',8' nomirror
set title 'clothsim threads under load: 0, 1, 2 busy processes beside each path and size'
plot csv using 0:9:xticlabels(sprintf("%s %d, %d busy", strcol(1), column(2), column(3))) skip 1 \
         with linespoints pt 7 ps 1.2 lc rgb '#1f77b4' title 'default / faster of 1 and 2 threads (target <= 1.15)', \
     csv using 0:10 skip 1 with linespoints pt 5 ps 1.0 lc rgb '#d62728' title '2 threads / 1 thread (target <= 2 with 2 busy)', \
     1.15 with lines dt 2 lc rgb '#1f77b4' notitle, \
     2.0 with lines dt 2 lc rgb '#d62728' notitle
