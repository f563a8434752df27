# Figure ch05_convergence (chapter 5): the natural-map residual ‖F‖/‖c‖ of JOR, SOR, APGD and
# Newton against the iteration (logarithmic: Newton's few iterations and the prox solvers'
# thousands on one axis). Left: a frictional two-layer pile (256 spheres, μ = 0.5), the second
# step's problem solved cold (solid) and warm-started from the first step (dashed). Middle: a deep
# frictionless pile (1024 spheres, eight layers). Right: the same block with μ = 0.5, the hard
# case.
#
# Data: convergence.csv, deep.csv and hard.csv from the demo ch05_convergence (convergence.cpp).
# Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" convergence.gp
if (!exists("datadir") || !exists("outfile")) {
  print "convergence.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" convergence.gp"
  exit status 2
}

friction = sprintf("%s/convergence.csv", datadir)
deep = sprintf("%s/deep.csv", datadir)
hard = sprintf("%s/hard.csv", datadir)

set terminal svg size 1400,450 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma
set datafile missing ""
set logscale xy
set format y "10^{%L}"
set yrange [1e-7:2]
set grid xtics ytics
set xlabel "iteration k"
set ylabel "‖F‖ / ‖c‖"
set key bottom left opaque box font 'sans,10'

set multiplot layout 1,3
set key top right
set title "frictional pile, μ = 0.5 (256 spheres, 1058 contacts)"
plot friction using 1:2 with lines lw 2 lc rgb "#0072b2" title "SOR", \
     friction using 1:3 with lines lw 2 lc rgb "#e69f00" title "JOR (α = 0.3, global r)", \
     friction using 1:4 with lines lw 2 lc rgb "#009e73" title "APGD", \
     friction using 1:5 with linespoints lw 2 pt 7 ps 0.5 lc rgb "#cc79a7" title "Newton (GMRES)", \
     friction using 1:6 with lines lw 2 dt 2 lc rgb "#0072b2" title "SOR, warm start", \
     friction using 1:7 with lines lw 2 dt 2 lc rgb "#e69f00" title "JOR, warm start", \
     friction using 1:8 with lines lw 2 dt 2 lc rgb "#009e73" title "APGD, warm start", \
     friction using 1:9 with linespoints lw 2 dt 2 pt 6 ps 0.5 lc rgb "#cc79a7" title "Newton, warm start"
set title "deep frictionless pile (1024 spheres, 5288 contacts)"
set key bottom right
set yrange [1e-11:2]
plot deep using 1:2 with lines lw 2 lc rgb "#0072b2" title "SOR", \
     deep using 1:3 with lines lw 2 lc rgb "#e69f00" title "JOR (α = 0.3, global r)", \
     deep using 1:4 with lines lw 2 lc rgb "#009e73" title "APGD", \
     deep using 1:5 with linespoints lw 2 pt 7 ps 0.5 lc rgb "#cc79a7" title "Newton (GMRES)"
set title "deep frictional pile, μ = 0.5 (1024 spheres)"
set key bottom left
set yrange [1e-4:2]
plot hard using 1:2 with lines lw 2 lc rgb "#0072b2" title "SOR", \
     hard using 1:3 with lines lw 2 lc rgb "#009e73" title "APGD", \
     hard using 1:4 with linespoints lw 2 pt 7 ps 0.5 lc rgb "#cc79a7" title "Newton (GMRES)"
unset multiplot
