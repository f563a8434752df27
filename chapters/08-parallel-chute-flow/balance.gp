# Figure ch08_balance (chapter 8): 20 000 bodies heaped against a corner of a 0.4 m × 0.4 m box,
# seen from above, coloured by the process that owns them among four, with the subdomains' outlines.
# Left: the grid balanced by weighted quantiles along each axis. Right: the tree of recursive
# coordinate bisection balanced by weight.
#
# Data: balance.csv and cuts.csv from the demo ch08_balance (balance.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" balance.gp
if (!exists("datadir") || !exists("outfile")) {
  print "balance.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" balance.gp"
  exit status 2
}

data = sprintf("%s/balance.csv", datadir)
cuts = sprintf("%s/cuts.csv", datadir)

set terminal svg size 900,460 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set xrange [0:0.4]
set yrange [0:0.4]
set size ratio -1
set xlabel "x [m]"
set ylabel "y [m]"
colour(k) = k == 0 ? 0x0072b2 : k == 1 ? 0xe69f00 : k == 2 ? 0x009e73 : 0xcc79a7
box(layout, k) = layout == k ? 1 : NaN

set multiplot layout 1,2
set title "balanced grid: quantiles along x and y"
plot data every 2 using 1:2:(colour($3)) with points pt 7 ps 0.25 lc rgb variable notitle, \
     cuts using (($3 + $5) / 2 * box($1, 1)):(($4 + $6) / 2):(($5 - $3) / 2):(($6 - $4) / 2) \
       with boxxyerror fs empty lw 2 lc rgb "#202020" notitle
set title "bisection tree: each cut halves its box's weight"
plot data every 2 using 1:2:(colour($4)) with points pt 7 ps 0.25 lc rgb variable notitle, \
     cuts using (($3 + $5) / 2 * box($1, 2)):(($4 + $6) / 2):(($5 - $3) / 2):(($6 - $4) / 2) \
       with boxxyerror fs empty lw 2 lc rgb "#202020" notitle
unset multiplot
