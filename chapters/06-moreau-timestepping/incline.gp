# Figure ch06_incline (chapter 6): a block (μ = 0.5) on a slope at θ_c − 0.1° and θ_c + 0.1°,
# θ_c = atan μ, stepped by MoreauStepper with Δt = 1 ms: its velocity along the slope against time
# and the closed form g(sin θ − μ cos θ) t above the friction angle (at rest below it).
#
# Data: incline.csv from the demo ch06_validation (validation.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" incline.gp
if (!exists("datadir") || !exists("outfile")) {
  print "incline.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" incline.gp"
  exit status 2
}

data = sprintf("%s/incline.csv", datadir)

set terminal svg size 800,450 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set grid xtics ytics
set key top left opaque box font 'sans,11'
set xlabel "time t [s]"
set ylabel "velocity along the slope [mm/s]"
plot data using 1:(1e3*$3) every 20 with points pt 7 ps 0.5 lc rgb "#d55e00" title "Moreau, θ_c + 0.1°", \
     data using 1:(1e3*$4) with lines lw 1 dt 2 lc rgb "#000000" title "g (sin θ − μ cos θ) t", \
     data using 1:(1e3*$2) with lines lw 2 lc rgb "#0072b2" title "Moreau, θ_c − 0.1° (at rest)"
