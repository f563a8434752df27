# Figure ch07_beverloo (chapter 7): Beverloo's discharge (beverloo.toml). Left: the mass the
# outlet removed below the orifice against time, one curve per orifice diameter D. Right: the
# steady mass flow rate W (slope after t_start, error bars from batch means) against D, with
# Beverloo's law W = C ρ_b √g (D − k d)^(5/2) for the fitted C and k and for the values of
# Beverloo, Leniger and van de Velde (1961), C = 0.58, k = 1.5.
#
# Data: discharge.csv, beverloo.csv and beverloo_curve.csv from the demo ch07_beverloo
# (beverloo.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" beverloo.gp
if (!exists("datadir") || !exists("outfile")) {
  print "beverloo.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" beverloo.gp"
  exit status 2
}

series = sprintf("%s/discharge.csv", datadir)
table = sprintf("%s/beverloo.csv", datadir)
curve = sprintf("%s/beverloo_curve.csv", datadir)
# The column headers name the diameters: "mass_kg_D20mm" -> "D = 20 mm".
columns = system(sprintf("head -1 %s | wc -w", series)) - 2

set terminal svg size 1000,420 dynamic enhanced font 'sans,12'
set output outfile
set multiplot layout 1,2
set grid xtics ytics
set key top left opaque box font 'sans,11'
set xlabel "t [s]"
set ylabel "discharged mass [g]"
plot for [c=2:columns+1] series using 1:(1e3*column(c)) with lines lw 2 \
     title sprintf("D = %s mm", system(sprintf("head -1 %s | awk '{print $%d}' | sed 's/mass_kg_D//; s/mm//'", series, c+1)))
set xlabel "orifice diameter D [mm]"
set ylabel "mass flow rate W [g/s]"
set xrange [*:*]
plot table using (1e3*$1):(1e3*$2):(1e3*$3) with yerrorbars pt 7 ps 0.9 lc rgb "#0072b2" title "measured", \
     curve using (1e3*$1):(1e3*$2) with lines lw 2 lc rgb "#d55e00" title "Beverloo, fitted C and k", \
     curve using (1e3*$1):(1e3*$3) with lines lw 1 dt 2 lc rgb "#000000" title "Beverloo, C = 0.58, k = 1.5"
unset multiplot
