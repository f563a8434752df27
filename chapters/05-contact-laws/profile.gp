# Figure ch05_profile (chapter 5): the performance profile of SOR, APGD, Newton and the hybrid
# over the chapter's problems: the fraction ρ_s(τ) of problems that solver s solves within τ
# times the fastest solver's time.
#
# Data: profile.csv from ch05_profile (profile.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" profile.gp
if (!exists("datadir") || !exists("outfile")) {
  print "profile.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" profile.gp"
  exit status 2
}

data = sprintf("%s/profile.csv", datadir)

set terminal svg size 900,560 dynamic enhanced font 'sans,19'
set output outfile
set datafile separator comma
set logscale x 2
set format x "%g"
set xrange [1:*]
set yrange [0:1.02]
set grid xtics ytics
set key bottom right
set xlabel "τ (time relative to the fastest solver)"
set ylabel "ρ_s(τ): fraction of problems solved"
plot data using 1:2 with steps lw 3 lc rgb "#0072b2" title "SOR", \
     data using 1:3 with steps lw 3 lc rgb "#009e73" title "APGD", \
     data using 1:4 with steps lw 3 lc rgb "#cc79a7" title "Newton", \
     data using 1:5 with steps lw 3 lc rgb "#d55e00" dt 2 title "Hybrid"
