# Figure ch06_bouncing_ball (chapter 6): a ball dropped from a gap of 1 m onto the floor, stepped by
# MoreauStepper with Δt = 1 ms, for ε_N = 0.8 and 0.5. Top: the gap against time (lines), the
# closed-form flight arcs (dashed), the closed-form impact times (triangles) and the Zeno times
# (vertical lines). Bottom: the mechanical energy above rest relative to the start after each step,
# with the closed form ε^(2k) after impact k (dashed: the closed-form gap's energy).
#
# Data: bouncing_ball.csv, impacts.csv and zeno.csv from the demo ch06_validation
# (validation.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" bouncing_ball.gp
if (!exists("datadir") || !exists("outfile")) {
  print "bouncing_ball.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" bouncing_ball.gp"
  exit status 2
}

ball = sprintf("%s/bouncing_ball.csv", datadir)
impacts = sprintf("%s/impacts.csv", datadir)
zeno = sprintf("%s/zeno.csv", datadir)
set datafile separator comma
# The Zeno time of ε = 0.8 is the larger of the two.
stats zeno using 2 nooutput
zeno08 = STATS_max
zeno05 = STATS_min

set terminal svg size 1000,650 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set datafile missing ""
set grid xtics ytics
set key top right opaque box font 'sans,11'
set xrange [0:4.5]

set multiplot layout 2,1
set ylabel "gap above the floor [m]"
set yrange [-0.05:1.05]
set arrow 1 from zeno08, graph 0 to zeno08, graph 1 nohead dt 3 lc rgb "#0072b2"
set arrow 2 from zeno05, graph 0 to zeno05, graph 1 nohead dt 3 lc rgb "#d55e00"
set label 1 "Zeno time, ε = 0.8" at zeno08, graph 0.6 right offset -0.5,0 tc rgb "#0072b2"
set label 2 "Zeno time, ε = 0.5" at zeno05, graph 0.6 left offset 0.5,0 tc rgb "#d55e00"
plot ball using 1:2 with lines lw 2 lc rgb "#0072b2" title "Moreau, ε = 0.8", \
     ball using 1:3 with lines lw 1 dt 2 lc rgb "#000000" title "closed form", \
     ball using 1:5 with lines lw 2 lc rgb "#d55e00" title "Moreau, ε = 0.5", \
     ball using 1:6 with lines lw 1 dt 2 lc rgb "#000000" notitle, \
     impacts using 2:(0) with points pt 9 ps 0.9 lc rgb "#0072b2" title "closed-form impact times", \
     impacts using 4:(0) with points pt 9 ps 0.9 lc rgb "#d55e00" notitle
unset label 1
unset label 2
set xlabel "time t [s]"
set ylabel "(E − E_{rest}) / (E_0 − E_{rest})"
set yrange [-0.05:1.05]
plot ball using 1:4 with lines lw 2 lc rgb "#0072b2" title "ε = 0.8", \
     ball using 1:7 with lines lw 2 lc rgb "#d55e00" title "ε = 0.5"
unset multiplot
