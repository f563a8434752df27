# Figure ch05_fclib (chapter 5): the natural-map residual ‖F‖/‖q‖ of grbd's solvers on the three
# FCLIB problems of shared/data/fclib, from λ = 0, against the iteration.
#
# Data: fclib.csv from the bench program ch05_fclib (fclib.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" fclib.gp
if (!exists("datadir") || !exists("outfile")) {
  print "fclib.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" fclib.gp"
  exit status 2
}

data = sprintf("%s/fclib.csv", datadir)

set terminal svg size 1200,420 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set logscale xy
set format y "10^{%L}"
set format x "10^{%L}"
set yrange [1e-11:10]
set grid xtics ytics
set xlabel "iteration k"
set ylabel "‖F‖ / ‖q‖"
set key bottom left opaque box font 'sans,9'
pick(p, s, col_p, col_s, y) = (strcol(col_p) eq p && strcol(col_s) eq s) ? y : NaN

problems = "LMGC_100_PR_PerioBox-i00361-60-03000 Capsules-i125-1213 Spheres-i099-356-679"
titles = "PerioBox-60|Capsules-286|Spheres-356"
solvers = "SOR-AC SOR-DS JOR APGD"
colours = "#0072b2 #d55e00 #e69f00 #009e73"

set multiplot layout 1,3
do for [p = 1:3] {
  problem = word(problems, p)
  set title sprintf("%s", problem) noenhanced font 'sans,10'
  plot for [s = 1:4] data using 3:(pick(problem, word(solvers, s), 1, 2, $4)) \
       with lines lw 2 lc rgb word(colours, s) title word(solvers, s)
}
unset multiplot
