# Figure ch08_chute_steps (chapter 8): the solver's work through the run of the reference chute —
# contacts, sweeps of the SOR solver (capped at the scene's max_iterations) and the penetration
# per step (the largest and the mean over the contacts), against the time after the release.
#
# Data: steps.csv and values.txt from the demo ch08_chute (chute_flow.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" chute_steps.gp
if (!exists("datadir") || !exists("outfile")) {
  print "chute_steps.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" chute_steps.gp"
  exit status 2
}

steps = sprintf("%s/steps.csv", datadir)
values = sprintf("%s/values.txt", datadir)
fetch(key) = system(sprintf("awk -F' = ' '$1 == \"%s\" {print $2}' %s", key, values))
release = real(fetch("release"))

set terminal svg size 1000,640 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator ","
set multiplot layout 3,1
set grid
set xrange [-release:*]
set lmargin 12
set key top right

set ylabel "contacts"
plot steps using ($1 - release):2 skip 1 every 5 with lines lw 1.5 lc rgb "#0072b2" notitle
set ylabel "sweeps"
set yrange [0:*]
plot steps using ($1 - release):3 skip 1 every 5 with lines lw 1 lc rgb "#e69f00" notitle
set ylabel "penetration [mm]"
set xlabel "time after the release [s]"
set logscale y
set format y "10^{%L}"
set yrange [1e-4:1]
plot steps using ($1 - release):6 skip 1 every 5 with lines lw 1 lc rgb "#cc0000" title "largest", \
     steps using ($1 - release):7 skip 1 every 5 with lines lw 1 lc rgb "#0072b2" title "mean over the contacts"
unset multiplot
