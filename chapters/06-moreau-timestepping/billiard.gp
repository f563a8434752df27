# Figure ch06_billiard (chapter 6): a pool ball launched sliding at v₀ = 2 m/s without spin on a
# cloth with μ = 0.2, stepped by MoreauStepper with Δt = 0.1 ms: the speed v of its centre, the
# rolling speed ω R and the slip v − ω R against time, with the closed-form time t* = 2v₀/(7μg)
# at which it starts to roll and the rolling speed (5/7) v₀.
#
# Data: billiard.csv from the demo ch06_validation (validation.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" billiard.gp
if (!exists("datadir") || !exists("outfile")) {
  print "billiard.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" billiard.gp"
  exit status 2
}

data = sprintf("%s/billiard.csv", datadir)
v0 = 2.0
mu = 0.2
g = 9.81
tstar = 2.0 * v0 / (7.0 * mu * g)

set terminal svg size 800,450 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set grid xtics ytics
set key center right opaque box font 'sans,11'
set xlabel "time t [s]"
set ylabel "velocity [m/s]"
set yrange [-0.1:2.1]
set arrow 1 from tstar, graph 0 to tstar, graph 1 nohead dt 3 lc rgb "#000000"
set label 1 "t* = 2v_0/(7μg)" at tstar, graph 0.95 left offset 0.5,0
set arrow 2 from graph 0, first 5.0/7.0*v0 to graph 1, first 5.0/7.0*v0 nohead dt 3 lc rgb "#000000"
set label 2 "(5/7) v_0" at graph 0.02, first 5.0/7.0*v0 offset 0,0.6
plot data using 1:2 with lines lw 2 lc rgb "#0072b2" title "v", \
     data using 1:3 with lines lw 2 lc rgb "#009e73" title "ω R", \
     data using 1:4 with lines lw 2 lc rgb "#d55e00" title "slip v − ω R"
