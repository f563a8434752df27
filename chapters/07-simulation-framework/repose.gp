# Figure ch07_repose (chapter 7): the angle of repose (repose.toml). Left: the surface of each heap
# at rest (the highest bead centre per bin one diameter wide) with the straight line fitted to its
# flanks. Right: the angle of repose θ against the friction coefficient μ between the beads, with
# the angle of one sliding contact, atan μ, and the angle μ_s = tan 20.9° of glass beads measured
# by Jop, Forterre and Pouliquen (2006).
#
# Data: profile.csv and repose.csv from the demo ch07_repose (repose.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" repose.gp
if (!exists("datadir") || !exists("outfile")) {
  print "repose.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" repose.gp"
  exit status 2
}

profile = sprintf("%s/profile.csv", datadir)
table = sprintf("%s/repose.csv", datadir)
heaps = system(sprintf("grep -vc '^#' %s", table))
# Column 1 of repose.csv is μ; 7 and 8 the line z = a + b |x|; 9 and 10 the fitted window.
mu(k) = real(system(sprintf("grep -v '^#' %s | sed -n %dp | awk '{print $1}'", table, k)))
a(k) = real(system(sprintf("grep -v '^#' %s | sed -n %dp | awk '{print $7}'", table, k)))
b(k) = real(system(sprintf("grep -v '^#' %s | sed -n %dp | awk '{print $8}'", table, k)))
x_min = real(system(sprintf("grep -v '^#' %s | sed -n 1p | awk '{print $9}'", table)))
x_max = real(system(sprintf("grep -v '^#' %s | sed -n 1p | awk '{print $10}'", table)))

set terminal svg size 1000,420 dynamic enhanced font 'sans,12'
set output outfile
set multiplot layout 1,2
set grid xtics ytics
set key top right opaque box font 'sans,10'
set xlabel "x [mm]"
set ylabel "surface: highest centre [mm]"
set yrange [0:*]
on_flank(x) = (abs(x) >= 1e3 * x_min && abs(x) <= 1e3 * x_max) ? 1 : NaN
plot for [k=1:heaps] profile using (1e3*$1):(1e3*column(k+1) > 0 ? 1e3*column(k+1) : NaN) \
       with points pt 7 ps 0.5 lc k title sprintf("μ = %g", mu(k)), \
     for [k=1:heaps] '+' using 1:(on_flank($1) * 1e3 * (a(k) + b(k) * abs($1) * 1e-3)) \
       with lines lw 1.5 lc k notitle
set xlabel "friction coefficient μ between the beads"
set ylabel "angle of repose θ [degrees]"
set key top left opaque box font 'sans,10'
set xrange [-0.05:1.05]
set yrange [0:60]  # room for the key above atan(1) = 45°
set samples 200
plot table using 1:2:3 with yerrorbars pt 7 ps 0.9 lc rgb "#0072b2" title "heap at rest", \
     atan(x) * 180 / pi with lines lw 1 dt 2 lc rgb "#000000" title "one sliding contact: atan μ", \
     20.9 with lines lw 1 dt 4 lc rgb "#d55e00" title "glass beads: μ_s = tan 20.9° (Jop et al. 2006)"
unset multiplot
