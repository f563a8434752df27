# Figure ch04_scaling (chapter 4): the cost of one broad-phase pass (CellGrid::build + find_pairs)
# per sphere against the number of spheres N, for spheres stored in random order and after Morton
# (Z-order) reordering, the part of it that is the build, and the cost of the reordering itself.
# A horizontal line is linear scaling, O(N).
#
# Data: scaling.csv from the demo ch04_scaling (scaling.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" scaling.gp
if (!exists("datadir") || !exists("outfile")) {
  print "scaling.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" scaling.gp"
  exit status 2
}

data = sprintf("%s/scaling.csv", datadir)

set terminal svg size 800,450 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set title "Broad phase: uniform grid of cell lists, solid fraction 0.55, radii 0.8–1 r_{max}" font 'sans,13'
set logscale x
set format x "10^{%L}"
set xrange [500:2e6]
set xlabel "number of spheres N"
set ylabel "time per sphere [ns]"
set yrange [0:*]
set grid xtics ytics
set key top left Left reverse opaque box font 'sans,11'

plot data using 1:2 with linespoints lw 2 pt 7 ps 1.2 lc rgb "#d55e00" title "random order in memory", \
     data using 1:3 with linespoints lw 2 pt 5 ps 1.2 lc rgb "#0072b2" title "after Morton (Z-order) reordering", \
     data using 1:7 with linespoints lw 1 dt 3 pt 7 ps 0.7 lc rgb "#d55e00" title "of which build, random order", \
     data using 1:9 with linespoints lw 1 dt 3 pt 5 ps 0.7 lc rgb "#0072b2" title "of which build, Morton order", \
     data using 1:5 with linespoints lw 1.5 dt 2 pt 6 ps 1.0 lc rgb "#009e73" title "cost of the reordering itself"
