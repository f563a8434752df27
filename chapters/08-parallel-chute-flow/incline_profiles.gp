# Figure ch08_incline_profiles (chapter 8): the steady flows on the rough incline (incline.toml)
# at each angle, across the depth z above the base: left, the velocity with Bagnold's profile
# u = A (h^{3/2} − (h − z)^{3/2}) fitted to it (lines); middle, the solid fraction; right, the ratio
# of the contact stresses σ_xz/σ_zz with tan θ (dashed).
#
# Data: profile_<θ>.csv and study.csv from the demo ch08_incline (incline.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" incline_profiles.gp
if (!exists("datadir") || !exists("outfile")) {
  print "incline_profiles.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" incline_profiles.gp"
  exit status 2
}

study = sprintf("%s/study.csv", datadir)
angles = system(sprintf("tail -n +2 %s | cut -d, -f1", study))
profile(a) = sprintf("%s/profile_%s.csv", datadir, a)
colour(i) = word("#0072b2 #e69f00 #009e73 #cc79a7 #d55e00 #56b4e9 #000000 #999999", (i - 1) % 8 + 1)

set terminal svg size 1000,440 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator ","
set multiplot layout 1,3
set grid
set ylabel "height above the base z [mm]"
set key top left font 'sans,10'

set xlabel "velocity u [m/s]"
plot for [i = 1:words(angles)] profile(word(angles, i)) using 3:($1 * 1e3) skip 1 \
       with points pt 7 ps 0.5 lc rgb colour(i) title sprintf("θ = %s°", word(angles, i)), \
     for [i = 1:words(angles)] profile(word(angles, i)) using 7:($1 * 1e3) skip 1 \
       with lines lw 1.5 lc rgb colour(i) notitle

set xlabel "solid fraction φ"
set xrange [0:0.7]
unset key
plot for [i = 1:words(angles)] profile(word(angles, i)) using 2:($1 * 1e3) skip 1 \
       with linespoints pt 7 ps 0.4 lc rgb colour(i) notitle

set xlabel "−σ_{xz}/σ_{zz}"
set xrange [0.2:0.8]
plot for [i = 1:words(angles)] profile(word(angles, i)) using 8:($1 * 1e3) skip 1 \
       with linespoints pt 7 ps 0.4 lc rgb colour(i) notitle, \
     for [i = 1:words(angles)] profile(word(angles, i)) using (tan(real(word(angles, i)) * pi / 180)):($1 * 1e3) skip 1 \
       with lines dt 2 lc rgb colour(i) notitle
unset multiplot
