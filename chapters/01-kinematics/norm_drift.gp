# Figure ch01_norm_drift (chapter 1): how far |p| leaves the unit sphere S³ when a body spinning
# with constant body angular velocity (|ω| = 2π rad/s) is integrated with explicit Euler and with
# the exponential map, against the exact law |p_n| = (1 + h²|ω|²/4)^(n/2) of explicit Euler.
#
# Data: drift_h<h>.csv from the demo ch01_norm_drift (norm_drift.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" norm_drift.gp
if (!exists("datadir") || !exists("outfile")) {
  print "norm_drift.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" norm_drift.gp"
  exit status 2
}

steps = "0.1 0.05 0.01"                # the step sizes of norm_drift.cpp [s], same spelling
colours = "#0072b2 #d55e00 #009e73"
file(i) = sprintf("%s/drift_h%s.csv", datadir, word(steps, i))
h(i) = word(steps, i) + 0
stride(i) = int(0.1 / h(i) + 0.5)      # about 100 markers per exp-map curve
positive(x) = (x > 0 ? x : NaN)        # log scale: |p| - 1 = 0 exactly is not drawn
after_start(x) = (column(2) > 0 ? positive(x) : NaN)   # column 2 is the step number n

set terminal svg size 800,500 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set xlabel "time t [s]"
set ylabel "distance from the unit sphere  | |p| − 1 |  [–]"
set xrange [0:10]
set logscale y
set yrange [1e-17:1e4]
set format y "10^{%L}"
set ytics 1e-16, 1e4
set mytics 4
set grid xtics ytics
set key center right Left reverse opaque box spacing 1.1 font 'sans,12' maxrows 4

plot for [i=1:3] file(i) using 1:(after_start($3 - 1)) with lines lw 2 lc rgb word(colours, i) \
       title sprintf("explicit Euler, h = %s s", word(steps, i)), \
     for [i=1:3] file(i) using 1:(after_start($4 - 1)) with lines dt 2 lw 1.5 lc rgb "black" \
       title (i == 1 ? "law (1 + h^2|ω|^2/4)^{n/2} − 1" : ""), \
     for [i=1:3] file(i) every stride(i) using 1:(after_start(abs($5))) \
       with points pt 7 ps 0.35 lc rgb word(colours, i) \
       title sprintf("exp map, h = %s s", word(steps, i))
