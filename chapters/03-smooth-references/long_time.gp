# Figure ch03_long_time (chapter 3): drift against bounded oscillation. A torque-free asymmetric
# body (K_Theta = (2, 3, 4) kg m²) turning 20 times a second, followed for 10⁴ turns: the relative
# errors of the kinetic energy (top) and of |L| (bottom), each the maximum over an output window
# (4 turns or 2 % of the time, whichever is longer), for
# three integrators of chapter 2 at h = 1 ms and for CVODE (BDF and Adams) at rtol 1e-6.
#
# Data: <method>.csv from the demo ch03_long_time (long_time.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" long_time.gp
if (!exists("datadir") || !exists("outfile")) {
  print "long_time.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" long_time.gp"
  exit status 2
}

names = "explicit_exp_map lie_poisson implicit_gyroscopic cvode_bdf cvode_adams"
array labels[5] = ["(a) explicit exp map, h = 1 ms (= (b), (c))", \
                   "(d) Lie–Poisson splitting, h = 1 ms", \
                   "(e) implicit gyroscopic, h = 1 ms", "CVODE BDF, rtol 10^{-6}", \
                   "CVODE Adams, rtol 10^{-6}"]
colours = "#0072b2 #009e73 #e69f00 #000000 #777777"
dashes = "1 1 1 1 2"
widths = "2 2 2 1.5 1.5"
file(i) = sprintf("%s/%s.csv", datadir, word(names, i))
positive(x) = (x > 0 ? x : NaN)   # log scale: an error of exactly 0 is not drawn

set terminal svg size 800,760 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xrange [3:1e4]
set mytics 10
set grid xtics ytics
set lmargin 12
set rmargin 3

set multiplot layout 2,1 \
    title "10^4 turns of a torque-free asymmetric body (one turn: 0.05 s)" font 'sans,13'

set format x ""
set ylabel "energy:  max |E − E(0)| / E(0)"
set yrange [1e-10:1e4]
set ytics 1e-10, 100
set key bottom right Left reverse opaque box font 'sans,12' spacing 1.0 samplen 2.5
plot for [i=1:5] file(i) using 2:(positive($3)) with lines lw word(widths, i) \
       dt int(word(dashes, i)) lc rgb word(colours, i) title labels[i]

unset key
set format x "10^{%L}"
set xlabel "time t / (one turn)"
set ylabel "angular momentum:  max | |L| − |L(0)| | / |L(0)|"
set yrange [1e-16:1e4]
set ytics 1e-16, 100
plot for [i=1:5] file(i) using 2:(positive($4)) with lines lw word(widths, i) \
       dt int(word(dashes, i)) lc rgb word(colours, i) notitle

unset multiplot
