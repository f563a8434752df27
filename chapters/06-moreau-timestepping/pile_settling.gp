# Figure ch06_pile_settling (chapter 6): 216 glass spheres (r = 1 mm, μ = 0.5) dropped from a
# jittered lattice into an open box, stepped by MoreauStepper with Δt = 0.2 ms and the default
# solver options (SOR, percussion change ≤ 10⁻⁶ relative, at most 1000 iterations), once with the
# warm start (solid) and once without (dashed). Per step: the kinetic energy, the active contacts,
# the solver iterations, and the natural-map residual ‖F‖ the solver returned.
#
# Data: pile.csv from the demo ch06_validation (validation.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" pile_settling.gp
if (!exists("datadir") || !exists("outfile")) {
  print "pile_settling.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" pile_settling.gp"
  exit status 2
}

data = sprintf("%s/pile.csv", datadir)

set terminal svg size 1000,650 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set grid xtics ytics
set key opaque box font 'sans,11'
set xlabel "time t [s]"

set multiplot layout 2,2
set logscale y
set format y "10^{%L}"
set ylabel "kinetic energy [J]"
set key top right
plot data using 2:3 with lines lw 2 lc rgb "#0072b2" title "warm start", \
     data using 2:9 with lines lw 1 dt 2 lc rgb "#d55e00" title "cold start"
unset logscale y
set format y "%g"
set ylabel "active contacts"
set key bottom right
plot data using 2:4 with lines lw 2 lc rgb "#0072b2" title "warm start", \
     data using 2:10 with lines lw 1 dt 2 lc rgb "#d55e00" title "cold start"
set ylabel "SOR iterations"
set yrange [0:1050]
set key center right
plot data using 2:11 with points pt 7 ps 0.25 lc rgb "#d55e00" title "cold start", \
     data using 2:5 with points pt 7 ps 0.25 lc rgb "#0072b2" title "warm start"
set yrange [1e-9:1e-3]
set logscale y
set format y "10^{%L}"
set ylabel "natural-map residual ‖F‖"
set key top right
plot data using 2:($14 > 0 ? $14 : NaN) with points pt 7 ps 0.25 lc rgb "#d55e00" title "cold start", \
     data using 2:($8 > 0 ? $8 : NaN) with points pt 7 ps 0.25 lc rgb "#0072b2" title "warm start"
unset multiplot
