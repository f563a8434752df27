# Figure ch08_chute_flow (chapter 8): the run of the reference chute (chute.toml). Left: the flow
# count F(t), the beads past the kink, against the time after the gate opened, with the entry
# (150 beads), 1 % and 95 % marked. Right: the front — the distance along the floors from the
# top of the upper chute to the leading beads — and its speed until it reaches the outlet; the
# kink, the first tree and the outlet.
#
# Data: flow.csv and values.txt from the demo ch08_chute (chute_flow.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" chute_flow.gp
if (!exists("datadir") || !exists("outfile")) {
  print "chute_flow.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" chute_flow.gp"
  exit status 2
}

flow = sprintf("%s/flow.csv", datadir)
values = sprintf("%s/values.txt", datadir)
fetch(key) = system(sprintf("awk -F' = ' '$1 == \"%s\" {print $2}' %s", key, values))
beads = real(fetch("beads"))
release = real(fetch("release"))
kink = real(fetch("kink_m"))
tree = kink + real(fetch("first_tree_cm")) / 100.0
outlet = real(fetch("outlet_m"))

set terminal svg size 1000,420 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator ","
set multiplot layout 1,2
set grid
set xlabel "time after the release t − t_{gate} [s]"
set xrange [0:*]

set ylabel "beads past the kink F"
set key bottom right
set yrange [0:beads * 1.05]
do for [key in "entry first last"] {
  v = fetch(key)
  if (v ne "never") {
    set arrow from real(v) - release, graph 0 to real(v) - release, graph 1 nohead dt 3 lc rgb "#808080"
  }
}
plot flow using 2:4 skip 1 with linespoints pt 7 ps 0.4 lw 2 lc rgb "#0072b2" title "F(t)", \
     beads * 0.95 with lines dt 2 lc rgb "#cc0000" title "95 %", \
     beads * 0.01 with lines dt 2 lc rgb "#e69f00" title "1 %"
unset arrow

set ylabel "front along the floors [m]"
set y2label "front speed [m/s]"
set ytics nomirror
set y2tics
set yrange [0:*]
set y2range [0:*]
set key bottom right
set yrange [0:1]
# The speed until the front reaches the outlet, which removes the beads ahead.
plot flow using 2:5 skip 1 with lines lw 2 lc rgb "#0072b2" title "front", \
     kink with lines dt 2 lc rgb "#808080" title "kink", \
     tree with lines dt 3 lc rgb "#009e73" title "first tree", \
     outlet with lines dt 4 lc rgb "#cc0000" title "outlet", \
     flow using 2:($5 < outlet - 0.06 ? $6 : NaN) skip 1 axes x1y2 with linespoints pt 7 ps 0.4 lc rgb "#e69f00" title "front speed"
unset multiplot
