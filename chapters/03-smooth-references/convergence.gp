# Figure ch03_convergence (chapter 3): the convergence study. The error at T = 10 s of every
# integrator of chapter 2 on a torque-free asymmetric body (K_Theta = (2, 3, 4) kg m²,
# K_omega(0) = (1, 1, 1) rad/s) against a CVODE reference (BDF, rtol 1e-12), as a function of the
# step h. Left: the angle between the computed and the reference orientation; right: the error
# of the body angular velocity. Dotted: reference slopes 1 and 2.
#
# Data: <integrator>.csv from the demo ch03_convergence (convergence.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" convergence.gp
if (!exists("datadir") || !exists("outfile")) {
  print "convergence.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" convergence.gp"
  exit status 2
}

# The integrators in the order of grbd::body::integrators(), with the labels and colours of
# chapter 2.
names = "explicit_exp_map symplectic_exp_map explicit_euler_normalized " . \
        "lie_poisson implicit_gyroscopic"
array labels[5] = ["(a) explicit exp map", "(b) symplectic exp map", \
                   "(c) explicit Euler + normalisation", "(d) Lie–Poisson splitting", \
                   "(e) implicit gyroscopic"]
colours = "#0072b2 #d55e00 #cc79a7 #009e73 #e69f00"
dashes = "1 2 4 1 1"
points = "7 5 9 11 13"
file(i) = sprintf("%s/%s.csv", datadir, word(names, i))
set datafile separator comma

# Reference slopes through points below the data: C h and C h², anchored at h = 0.1 s.
stats file(1) using 1:3 nooutput
c1 = STATS_max_y / 0.1 / 4.0
stats file(4) using 1:3 nooutput
c2 = STATS_max_y / 0.01 / 4.0
stats file(1) using 1:4 nooutput
d1 = STATS_max_y / 0.1 / 4.0
stats file(4) using 1:4 nooutput
d2 = STATS_max_y / 0.01 / 4.0

set terminal svg size 900,540 dynamic enhanced font 'sans,12'
set output outfile

set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set xrange [2e-4:0.2]
set grid xtics ytics
set xlabel "step size h [s]"
unset key

set multiplot title "Convergence at T = 10 s, torque-free asymmetric body" font 'sans,13'
set size 0.5, 0.76
set origin 0.0, 0.18
set ylabel "orientation error at T [rad]"
plot for [i=1:5] file(i) using 1:3 with linespoints lw 1.5 dt int(word(dashes, i)) \
       pt int(word(points, i)) ps 0.6 lc rgb word(colours, i) notitle, \
     c1 * x with lines dt 3 lw 1 lc rgb "#555555" notitle, \
     c2 * x**2 with lines dt 3 lw 1 lc rgb "#999999" notitle

set origin 0.5, 0.18
set ylabel "angular velocity error |ω(T) − ω_{ref}(T)| [rad/s]"
plot for [i=1:5] file(i) using 1:4 with linespoints lw 1.5 dt int(word(dashes, i)) \
       pt int(word(points, i)) ps 0.6 lc rgb word(colours, i) notitle, \
     d1 * x with lines dt 3 lw 1 lc rgb "#555555" notitle, \
     d2 * x**2 with lines dt 3 lw 1 lc rgb "#999999" notitle

# The key, below both panels.
set size 1.0, 0.18
set origin 0.0, 0.0
unset border
unset tics
unset xlabel
unset ylabel
unset grid
unset logscale
set xrange [0:1]
set yrange [0:1]
set key center center horizontal maxrows 3 Left reverse font 'sans,12' samplen 2.5 \
    spacing 1.1 width 1
plot for [i=1:5] NaN with linespoints lw 1.5 dt int(word(dashes, i)) \
       pt int(word(points, i)) ps 0.6 lc rgb word(colours, i) title labels[i], \
     NaN with lines dt 3 lw 1 lc rgb "#555555" title "slope 1", \
     NaN with lines dt 3 lw 1 lc rgb "#999999" title "slope 2"

unset multiplot
