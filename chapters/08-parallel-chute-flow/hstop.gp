# Figure ch08_hstop (chapter 8): where layers on the rough incline stop. Left, every layer of
# glass beads (μ = 0.5) by its angle θ and depth h/d: those that flow, those that creep and those
# at rest, with the bracket of h_stop(θ) between the deepest layer that does not flow and the
# shallowest that does. Middle, Pouliquen's flow rule: the Froude number ū/√(gh) of every flowing
# layer against h/h_stop(θ) (h_stop at the middle of its bracket, the bar its ends), the
# line of β fitted and Pouliquen's β = 0.136. Right, the frictionless layers the same way as the
# left.
#
# Data: layers.csv, hstop.csv, rule.csv and values.txt from the demo ch08_hstop (hstop.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" hstop.gp
if (!exists("datadir") || !exists("outfile")) {
  print "hstop.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" hstop.gp"
  exit status 2
}

values = sprintf("%s/values.txt", datadir)
fetch(key) = system(sprintf("awk -F' = ' '$1 == \"%s\" {print $2}' %s", key, values))
layers = sprintf("%s/layers.csv", datadir)
beta = real(fetch("rule.beta"))

set terminal svg size 1200,420 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator ","
set multiplot layout 1,3
set grid
set key top left font 'sans,10'

set xlabel "angle θ [°]"
set ylabel "depth h/d"
set xrange [20:28]
set yrange [0:19]
set title "glass beads, μ = 0.5"
plot sprintf("%s/hstop.csv", datadir) using 1:(($2 + $3) / 2):2:3 skip 1 with yerrorbars \
       pt 0 lw 4 lc rgb "#b0b0b0" title "h_{stop} between", \
     layers using 2:($4 != 0 && strcol(9) eq "flowing" ? $5 : NaN) skip 1 with points pt 7 ps 1.2 \
       lc rgb "#0072b2" title "flows", \
     layers using 2:($4 != 0 && strcol(9) eq "creeping" ? $5 : NaN) skip 1 with points pt 8 ps 1.2 \
       lc rgb "#e69f00" title "creeps", \
     layers using 2:($4 != 0 && strcol(9) eq "rest" ? $5 : NaN) skip 1 with points pt 6 ps 1.2 \
       lc rgb "#d55e00" title "at rest"

set xlabel "h / h_{stop}(θ)"
set ylabel "Froude number ū/√(gh)"
set xrange [0:12]
set yrange [0:1.2]
set key top left
set title "Pouliquen's flow rule"
plot sprintf("%s/rule.csv", datadir) using 4:5:6:7 skip 1 with xerrorbars pt 7 ps 1.2 \
       lc rgb "#0072b2" title "flowing layers", \
     beta * x with lines lw 2 lc rgb "#cc0000" title sprintf("fit: β = %s", fetch("rule.beta")), \
     0.136 * x with lines dt 2 lw 2 lc rgb "#808080" title "Pouliquen 1999: β = 0.136"

set xlabel "angle θ [°]"
set ylabel "depth h/d"
set xrange [5:15]
set yrange [0:19]
set key top left
set title "frictionless beads, μ = 0"
plot layers using 2:($4 == 0 && strcol(9) eq "flowing" ? $5 : NaN) skip 1 with points pt 7 ps 1.2 \
       lc rgb "#0072b2" title "flows", \
     layers using 2:($4 == 0 && strcol(9) eq "creeping" ? $5 : NaN) skip 1 with points pt 8 ps 1.2 \
       lc rgb "#e69f00" title "creeps", \
     layers using 2:($4 == 0 && strcol(9) eq "rest" ? $5 : NaN) skip 1 with points pt 6 ps 1.2 \
       lc rgb "#d55e00" title "at rest"
unset multiplot
