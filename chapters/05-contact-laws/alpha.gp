# Figure ch05_alpha (chapter 5): the natural-map residual ‖F‖/‖c‖ of SOR with r = α/G_ii for
# α = 0.3 … 1.9, on the frictional two-layer pile (256 spheres, μ = 0.5), cold start.
#
# Data: alpha.csv from the demo ch05_convergence (convergence.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" alpha.gp
if (!exists("datadir") || !exists("outfile")) {
  print "alpha.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" alpha.gp"
  exit status 2
}

data = sprintf("%s/alpha.csv", datadir)

set terminal svg size 800,450 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set datafile missing ""
set logscale y
set format y "10^{%L}"
set yrange [1e-7:2]
set grid xtics ytics
set xlabel "iteration k"
set ylabel "‖F‖ / ‖c‖"
set key top right opaque box font 'sans,12'
set title "SOR with r = α / G_{ii}: the effect of the relaxation α"
plot for [col=2:7] data using 1:col with lines lw 2 title columnheader(col)
