# Figure ch01_orientation_error (chapter 1): the angle between the exact orientation of a body
# spinning with constant body angular velocity (|ω| = 2π rad/s) and the orientation R(p/|p|)
# computed by explicit Euler and by the exponential map. Explicit Euler turns p/|p| by
# 2 atan(h|ω|/2) instead of h|ω| per step, so it lags by n (h|ω| − 2 atan(h|ω|/2)) after n steps.
#
# Data: drift_h<h>.csv from the demo ch01_norm_drift (norm_drift.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" orientation_error.gp
if (!exists("datadir") || !exists("outfile")) {
  print "orientation_error.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" orientation_error.gp"
  exit status 2
}

steps = "0.1 0.05 0.01"                # the step sizes of norm_drift.cpp [s], same spelling
colours = "#0072b2 #d55e00 #009e73"
file(i) = sprintf("%s/drift_h%s.csv", datadir, word(steps, i))
h(i) = word(steps, i) + 0
stride(i) = int(0.1 / h(i) + 0.5)      # about 100 markers per exp-map curve
positive(x) = (x > 0 ? x : NaN)        # log scale: an error of exactly 0 is not drawn
after_start(x) = (column(2) > 0 ? positive(x) : NaN)   # column 2 is the step number n

set terminal svg size 800,500 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set xlabel "time t [s]"
set ylabel "orientation error: rotation angle to the exact A_{IK}(t)  [rad]"
set xrange [0:10]
set logscale y
set yrange [1e-17:1e4]
set format y "10^{%L}"
set ytics 1e-16, 1e4
set mytics 4
set grid xtics ytics
set key center right Left reverse opaque box spacing 1.1 font 'sans,12' maxrows 4

plot for [i=1:3] file(i) using 1:(after_start($6)) with lines lw 2 lc rgb word(colours, i) \
       title sprintf("explicit Euler (p/|p|), h = %s s", word(steps, i)), \
     for [i=1:3] file(i) using 1:(after_start($7)) with lines dt 2 lw 1.5 lc rgb "black" \
       title (i == 1 ? "law n (h|ω| − 2 atan(h|ω|/2))" : ""), \
     for [i=1:3] file(i) every stride(i) using 1:(after_start($8)) \
       with points pt 7 ps 0.35 lc rgb word(colours, i) \
       title sprintf("exp map, h = %s s", word(steps, i))
