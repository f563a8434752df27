# Figure ch02_dzhanibekov (chapter 2): the Dzhanibekov effect. A box with half-extents
# (0.08, 0.04, 0.01) m, spun at 2π rad/s about its intermediate principal axis with a 1 %
# perturbation, integrated torque-free by the Lie–Poisson splitting (h = 1 ms). The body-frame
# angular velocity components ω1, ω2, ω3; ω2 flips sign every 2K(m)/λ, and the predicted zeros of
# ω2 (Landau–Lifshitz §37) are marked.
#
# Data: omega.csv and flips.csv from the demo ch02_dzhanibekov (dzhanibekov.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" dzhanibekov.gp
if (!exists("datadir") || !exists("outfile")) {
  print "dzhanibekov.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" dzhanibekov.gp"
  exit status 2
}

omega = sprintf("%s/omega.csv", datadir)
flips = sprintf("%s/flips.csv", datadir)

set terminal svg size 800,450 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator comma

set xlabel "time t [s]"
set ylabel "body angular velocity _Kω [rad/s]"
set xrange [0:20]
set yrange [-8:8]
set ytics 2
set grid xtics ytics
set key outside top center horizontal Left reverse font 'sans,12' spacing 1.1

plot omega using 1:2 with lines lw 2 lc rgb "#0072b2" title "ω_1 (least moment Θ_1)", \
     omega using 1:3 with lines lw 2 lc rgb "#d55e00" title "ω_2 (intermediate Θ_2)", \
     omega using 1:4 with lines lw 2 lc rgb "#009e73" title "ω_3 (largest Θ_3)", \
     flips using 2:(0) with points pt 6 ps 1.2 lw 1.5 lc rgb "black" \
       title "predicted zeros of ω_2: (2Kj − u_0)/λ"
