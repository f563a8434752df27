# Figure ch08_incline_mu (chapter 8): left, the kinetic energy per bead through each run on the
# rough incline, the second half of which the profiles average; right, the friction law of the
# steady flows — the local stress ratio μ = σ_xz/σ_zz against the inertial number I = γ̇ d/√(P/ρ_s) of every slab
# of the bulk (20 % to 80 % of the depth) at every angle, the law of Jop, Forterre and Pouliquen
# (2006) fitted to them with μ_2 held at the glass beads' value, and the law with their constants (μ_s = tan 20.9°,
# μ_2 = tan 32.76°, I_0 = 0.279).
#
# Data: energy.csv, study.csv, mu_points.csv, mu_fit.csv and values.txt from the demo ch08_incline (incline.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" incline_mu.gp
if (!exists("datadir") || !exists("outfile")) {
  print "incline_mu.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" incline_mu.gp"
  exit status 2
}

values = sprintf("%s/values.txt", datadir)
fetch(key) = system(sprintf("awk -F' = ' '$1 == \"%s\" {print $2}' %s", key, values))
mu_s = tan(20.9 * pi / 180)
mu_2 = tan(32.76 * pi / 180)
law(I) = mu_s + (mu_2 - mu_s) / (0.279 / I + 1)

study = sprintf("%s/study.csv", datadir)
angles = system(sprintf("tail -n +2 %s | cut -d, -f1", study))
colour(i) = word("#0072b2 #e69f00 #009e73 #cc79a7 #d55e00 #56b4e9 #000000 #999999", (i - 1) % 8 + 1)

set terminal svg size 1000,440 dynamic enhanced font 'sans,12'
set output outfile
set datafile separator ","
set multiplot layout 1,2
set grid
set key top left font 'sans,10'
set xlabel "time t [s]"
set ylabel "kinetic energy per body [J]"
set logscale y
plot for [i = 1:words(angles)] sprintf("%s/energy.csv", datadir) \
       using 2:($1 == real(word(angles, i)) ? $3 : NaN) skip 1 with lines lw 1.5 lc rgb colour(i) \
       title sprintf("θ = %s°", word(angles, i))
unset logscale y

set logscale x
set xrange [1e-3:1]
set yrange [0.3:0.7]
set xlabel "inertial number I"
set ylabel "μ = −σ_{xz}/σ_{zz}"
plot sprintf("%s/mu_points.csv", datadir) using 1:2 skip 1 with points pt 7 ps 0.6 lc rgb "#0072b2" title "slabs of the bulk", \
     sprintf("%s/mu_fit.csv", datadir) using 1:2 skip 1 with lines lw 2 lc rgb "#cc0000" \
       title sprintf("fit (μ_2 of glass): μ_s = %s, I_0 = %s", fetch("fit.mu_s"), fetch("fit.i0")), \
     law(x) with lines dt 2 lw 2 lc rgb "#808080" title "glass beads (Jop et al. 2006)"
unset multiplot
