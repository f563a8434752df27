# Figure ch08_chute_field (chapter 8): the plan-view velocity field of the reference chute's run
# on the experiment's camera grid, in windows of 2 × 2 pixels, at the records where 10 %, 50 % and
# 90 % of the beads had passed the kink: the mean downstream speed of the beads seen in each
# window (white: no bead, outside the flow's mask), the downstream distance from the kink, and the
# three trees.
#
# Data: field1.dat … field3.dat, trees.dat and values.txt from the demo ch08_chute
# (chute_flow.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" chute_field.gp
if (!exists("datadir") || !exists("outfile")) {
  print "chute_field.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" chute_field.gp"
  exit status 2
}

values = sprintf("%s/values.txt", datadir)
fetch(key) = system(sprintf("awk -F' = ' '$1 == \"%s\" {print $2}' %s", key, values))
trees = sprintf("%s/trees.dat", datadir)

set terminal svg size 1000,760 dynamic enhanced font 'sans,12'
set output outfile
set multiplot layout 3,1
set xrange [0:62]
set yrange [-5:5]
set size ratio -1
set cbrange [0:2.5]
set cblabel "downstream speed [m/s]"
set palette defined (0 "#f7fbff", 0.2 "#c6dbef", 0.4 "#6baed6", 0.6 "#2171b5", 0.8 "#08306b", 1 "#000000")
set ylabel "y' [cm]"
do for [k = 1:3] {
  set title sprintf("%s %% past the kink: t − t_{gate} = %s s", fetch(sprintf("field%d.percent", k)), fetch(sprintf("field%d.after", k)))
  if (k == 3) { set xlabel "downstream of the kink [cm]" }
  plot sprintf("%s/field%d.dat", datadir, k) using 1:2:3 with image notitle, \
       trees using 1:2:3 with circles lc rgb "#cc0000" fs solid notitle
}
unset multiplot
