# Figure ch08_cost_model (chapter 8): predicted seconds per step of 10⁶ spheres at 1000 sweeps a
# step against the number of cores, with an InfiniBand and an Ethernet network, beside ideal
# scaling from one core and GRSFramework's published run (384 cores, about 4.8 s a step).
#
# Data: cost_model.csv from the demo ch08_cost_model (cost_model.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" cost_model.gp
if (!exists("datadir") || !exists("outfile")) {
  print "cost_model.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" cost_model.gp"
  exit status 2
}

data = sprintf("%s/cost_model.csv", datadir)

set terminal svg size 760,480 dynamic enhanced font 'sans,12'
set output outfile
set logscale xy
set xrange [16:4096]
set xlabel "cores P"
set ylabel "seconds per step (10^6 spheres, 1000 sweeps)"
set grid
set key top right
set label 1 "GRSFramework, 384 cores" at 400,5.6 left
plot data using 1:4 with lines dt 2 lw 1.5 lc rgb "#808080" title "ideal from one core", \
     data using 1:2 with linespoints pt 7 ps 0.6 lw 2 lc rgb "#0072b2" title "model, InfiniBand (2 µs, 5 GB/s)", \
     data using 1:3 with linespoints pt 5 ps 0.6 lw 2 lc rgb "#e69f00" title "model, gigabit Ethernet (50 µs, 0.1 GB/s)", \
     "-" using 1:2 with points pt 9 ps 1.6 lc rgb "#cc0000" title "published run"
384 4.8
e
