# Figure ch05_fclib (chapter 5): the natural-map residual ‖F‖/‖q‖ of grbd's solvers on the three
# FCLIB problems of chapters/05-contact-laws/data, from λ = 0, against the iteration.
#
# Data: fclib.csv from the bench program ch05_fclib (fclib.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" fclib.gp
if (!exists("datadir") || !exists("outfile")) {
  print "fclib.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" fclib.gp"
  exit status 2
}

data = sprintf("%s/fclib.csv", datadir)

set terminal svg size 1200,520 dynamic enhanced font 'sans,19'
set output outfile
set datafile separator comma
set logscale xy
set format y "10^{%L}"
set format x "10^{%L}"
set yrange [1e-11:10]
set grid xtics ytics
set xlabel "iteration k"
set ylabel "‖F‖ / ‖q‖"
pick(p, s, col_p, col_s, y) = (strcol(col_p) eq p && strcol(col_s) eq s) ? y : NaN

problems = "LMGC_100_PR_PerioBox-i00361-60-03000 Capsules-i125-1213 Spheres-i099-356-679"
titles = "PerioBox-60 Capsules-286 Spheres-356"
solvers = "SOR-AC SOR-DS JOR APGD Newton Newton-GMRES"
colours = "#0072b2 #d55e00 #e69f00 #009e73 #cc79a7 #000000"

set multiplot layout 1,3 margins 0.1,0.98,0.25,0.9 spacing 0.05,0
do for [p = 1:3] {
  problem = word(problems, p)
  set title sprintf("%s", word(titles, p)) noenhanced font 'sans,19'
  if (p == 1) { set ylabel "‖F‖ / ‖q‖" } else { unset ylabel }
  # No key in the panels: one legend in a row below them, drawn with the last panel.
  unset key
  if (p == 3) {
    do for [s = 1:6] {
      x0 = 0.03 + 0.155 * (s - 1)
      set arrow s from screen x0, 0.05 to screen x0 + 0.05, 0.05 nohead lw 3 lc rgb word(colours, s)
      set label s word(solvers, s) at screen x0 + 0.055, 0.05 left font 'sans,16'
    }
  }
  plot for [s = 1:6] data using 3:(pick(problem, word(solvers, s), 1, 2, $4)) \
       with lines lw 3 lc rgb word(colours, s) title word(solvers, s)
}
unset multiplot
