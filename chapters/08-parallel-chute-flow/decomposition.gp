# Figure ch08_decomposition (chapter 8): 4000 body centres in a chute's flow region (1 m × 0.2 m,
# seen from above), coloured by the process that owns them; filled when the body has a ghost copy
# on another process (it reaches within 1 cm of its subdomain). Top: the four slices grid_dims()
# chooses. Bottom: the 2 × 2 grid of MPI_Dims_create.
#
# Data: decomposition.csv from the demo ch08_decomposition (decomposition.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" decomposition.gp
if (!exists("datadir") || !exists("outfile")) {
  print "decomposition.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" decomposition.gp"
  exit status 2
}

data = sprintf("%s/decomposition.csv", datadir)

set terminal svg size 900,520 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set xrange [0:1]
set yrange [0:0.2]
set size ratio -1
set xlabel "x (along the flow) [m]"
set ylabel "y [m]"
colour(k) = k == 0 ? 0x0072b2 : k == 1 ? 0xe69f00 : k == 2 ? 0x009e73 : 0xcc79a7
set key outside right top

set multiplot layout 2,1
set title "grid\\_dims(): four slices across the flow"
plot data using 1:($4 > 0 ? NaN : $2):(colour($3)) with points pt 6 ps 0.45 lc rgb variable notitle, \
     data using 1:($4 > 0 ? $2 : NaN):(colour($3)) with points pt 7 ps 0.6 lc rgb variable notitle, \
     NaN with points pt 7 lc rgb "#404040" title "ghost elsewhere", \
     NaN with points pt 6 lc rgb "#404040" title "owned only"
set title "MPI\\_Dims\\_create: 2 × 2"
plot data using 1:($6 > 0 ? NaN : $2):(colour($5)) with points pt 6 ps 0.45 lc rgb variable notitle, \
     data using 1:($6 > 0 ? $2 : NaN):(colour($5)) with points pt 7 ps 0.6 lc rgb variable notitle, \
     NaN with points pt 7 lc rgb "#404040" title "ghost elsewhere", \
     NaN with points pt 6 lc rgb "#404040" title "owned only"
unset multiplot
