# Figure ch03_work_precision (chapter 3): work–precision diagrams. The orientation error at
# T = 10 s of a torque-free asymmetric body (K_Theta = (2, 3, 4) kg m², K_omega(0) = (1, 1, 1)
# rad/s) against the cost of the run: right-hand-side evaluations (left; for the fixed-step
# schemes of chapter 2, steps) and wall time (right). Chapter 2's schemes over h = 0.1 … 10⁻⁴ s,
# CVODE (BDF, Adams) and ARKODE's explicit Runge–Kutta methods of orders 2, 4 and 8 over
# rtol = atol = 10⁻³ … 10⁻¹⁰.
#
# Data: <method>.csv from the demo ch03_work_precision (work_precision.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" work_precision.gp
if (!exists("datadir") || !exists("outfile")) {
  print "work_precision.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" work_precision.gp"
  exit status 2
}

n = 10
names = "explicit_exp_map symplectic_exp_map explicit_euler_normalized " . \
        "lie_poisson implicit_gyroscopic cvode_bdf cvode_adams " . \
        "arkode_erk2 arkode_erk4 arkode_erk8"
array labels[10] = ["(a) explicit exp map", "(b) symplectic exp map", \
                    "(c) explicit Euler + normalisation", "(d) Lie–Poisson splitting", \
                    "(e) implicit gyroscopic", "CVODE BDF", "CVODE Adams", \
                    "ARKODE ERK, order 2", "ARKODE ERK, order 4", "ARKODE ERK, order 8"]
colours = "#0072b2 #d55e00 #cc79a7 #009e73 #e69f00 #000000 #777777 #56b4e9 #7b3294 #c2185b"
dashes = "1 2 4 1 1 1 2 1 1 1"
points = "7 5 9 11 13 4 6 8 10 12"
file(i) = sprintf("%s/%s.csv", datadir, word(names, i))

set terminal svg size 950,560 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set yrange [1e-12:10]
set ytics 1e-12, 100
set grid xtics ytics
set ylabel "orientation error at T [rad]"

set multiplot title "Work–precision, torque-free asymmetric body, T = 10 s" font 'sans,13'
set size 0.5, 0.73
set origin 0.0, 0.21
set xlabel "right-hand-side evaluations"
unset key
plot for [i=1:n] file(i) using 2:5 with linespoints lw 1.5 dt int(word(dashes, i)) \
       pt int(word(points, i)) ps 0.55 lc rgb word(colours, i) notitle

set origin 0.5, 0.21
set xlabel "wall time of one run [s]"
set ylabel ""
plot for [i=1:n] file(i) using 4:5 with linespoints lw 1.5 dt int(word(dashes, i)) \
       pt int(word(points, i)) ps 0.55 lc rgb word(colours, i) notitle

# The key, below both panels.
set size 1.0, 0.2
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
plot for [i=1:n] NaN with linespoints lw 1.5 dt int(word(dashes, i)) \
       pt int(word(points, i)) ps 0.55 lc rgb word(colours, i) title labels[i]

unset multiplot
