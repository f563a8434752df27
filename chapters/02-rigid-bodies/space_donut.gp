# Figure ch02_space_donut (chapter 2): a torus (R = 0.3 m, r = 0.1 m) tumbling torque-free for
# 300 s, integrated by every integrator of grbd::body with the same step h = 2 ms. Three panels:
# the relative error of the kinetic energy, of the angular momentum I_L in the inertial frame,
# and the distance of the quaternion from the unit sphere, each the maximum over 0.5 s.
#
# Data: <integrator>.csv from the demo ch02_space_donut (space_donut.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" space_donut.gp
if (!exists("datadir") || !exists("outfile")) {
  print "space_donut.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" space_donut.gp"
  exit status 2
}

# The integrators in the order of grbd::body::integrators(), and how the figure labels them.
names = "explicit_exp_map symplectic_exp_map explicit_euler_normalized lie_poisson implicit_gyroscopic"
array labels[5] = ["(a) explicit exp map", "(b) symplectic exp map", \
                   "(c) explicit Euler + normalisation", "(d) Lie–Poisson splitting", \
                   "(e) implicit gyroscopic"]
colours = "#0072b2 #d55e00 #cc79a7 #009e73 #e69f00"
dashes = "1 2 4 1 1"
widths = "2 2.5 1.5 2 2"
file(i) = sprintf("%s/%s.csv", datadir, word(names, i))
positive(x) = (x > 0 ? x : NaN)   # log scale: an error of exactly 0 is not drawn

set terminal svg size 800,900 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set logscale y
set format y "10^{%L}"
set mytics 10
set grid xtics ytics
set xrange [0:300]
set lmargin 12
set rmargin 3

set multiplot layout 3,1 title "Torque-free space donut, h = 2 ms, all integrators" font 'sans,13'

set key bottom right Left reverse opaque box font 'sans,12' maxrows 3 width -2
set format x ""
set ylabel "kinetic energy:  |T(t) − T(0)| / T(0)"
set yrange [1e-10:1e3]
set ytics 1e-9, 1e3
plot for [i=1:5] file(i) using 1:(positive($2)) with lines lw word(widths, i) \
       dt int(word(dashes, i)) lc rgb word(colours, i) title labels[i]

unset key
set ylabel "angular momentum in I:  |L(t) − L(0)| / |L(0)|"
set yrange [1e-16:1e1]
set ytics 1e-15, 1e3
plot for [i=1:5] file(i) using 1:(positive($3)) with lines lw word(widths, i) \
       dt int(word(dashes, i)) lc rgb word(colours, i) notitle

set format x "%g"
set xlabel "time t [s]"
set ylabel "quaternion:  | |p(t)| − 1 |"
set yrange [1e-17:1e-12]
set ytics 1e-17, 10
plot for [i=1:5] file(i) using 1:(positive($4)) with lines lw word(widths, i) \
       dt int(word(dashes, i)) lc rgb word(colours, i) notitle

unset multiplot
