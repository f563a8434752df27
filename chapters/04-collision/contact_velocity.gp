# Figure ch04_contact_velocity (chapter 4): a sphere (r = 0.1 m) flies past a tumbling box with
# half-extents (0.3, 0.2, 0.1) m. Top: the gap g_N, with the region of the box closest to the
# sphere's centre (face, edge or vertex) shaded. Middle: the normal contact velocity
# γ_N = W_aᵀu_a − W_bᵀu_b and the central difference of g_N. Bottom: their difference.
#
# Data: contact_velocity.csv from the demo ch04_contact_velocity (contact_velocity.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" contact_velocity.gp
if (!exists("datadir") || !exists("outfile")) {
  print "contact_velocity.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" contact_velocity.gp"
  exit status 2
}

data = sprintf("%s/contact_velocity.csv", datadir)

set terminal svg size 800,800 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set xrange [0:4]
set grid xtics ytics
set lmargin 12
set rmargin 3
only(r, region, y) = (r == region ? y : NaN)

set multiplot layout 3,1 title "Sphere past a tumbling box: γ_N = W^T u is the rate of the gap" font 'sans,13'

set format x ""
set ylabel "gap g_N [m]"
set key top center horizontal Left reverse opaque box font 'sans,12'
plot data using 1:(only($5, 1, $2)) with lines lw 3 lc rgb "#0072b2" title "face region", \
     data using 1:(only($5, 2, $2)) with lines lw 3 lc rgb "#e69f00" title "edge region", \
     data using 1:(only($5, 3, $2)) with lines lw 3 lc rgb "#d55e00" title "vertex region", \
     0 with lines lw 1 lc rgb "#808080" notitle

set ylabel "normal velocity [m/s]"
set key top center horizontal Left reverse opaque box font 'sans,12'
plot data using 1:3 with lines lw 2.5 lc rgb "#0072b2" title "γ_N = W_a^T u_a − W_b^T u_b", \
     data using 1:4 every 40 with points pt 6 ps 1.0 lc rgb "#d55e00" title "(g_N(t+δ) − g_N(t−δ)) / 2δ"

set format x "%g"
set xlabel "time t [s]"
set ylabel "|γ_N − ġ_N| [m/s]"
set logscale y
set format y "10^{%L}"
unset key
plot data using 1:(abs($3 - $4) > 0 ? abs($3 - $4) : NaN) with lines lw 1.5 lc rgb "#009e73" notitle

unset multiplot
