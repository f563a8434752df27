# Figure ch07_janssen (chapter 7): the vertical stress σ_v against the depth d below the free
# surface in a square silo filled with glass beads (silo.toml), from the contact percussions of the
# settled fill by Love's formula in slices two diameters thick; Janssen's law
# σ_v = ρ_b g λ (1 − e^(−d/λ)) with the fitted λ, and the hydrostatic ρ_b g d.
#
# Data: janssen.csv from the demo ch07_janssen (janssen.cpp). Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" janssen.gp
if (!exists("datadir") || !exists("outfile")) {
  print "janssen.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" janssen.gp"
  exit status 2
}

data = sprintf("%s/janssen.csv", datadir)

set terminal svg size 800,450 dynamic enhanced font 'sans,12'
set output outfile
set grid xtics ytics
set key top left opaque box font 'sans,11'
set xlabel "depth below the free surface d [mm]"
set ylabel "stress [Pa]"
plot data using (1e3*$1):2 with points pt 7 ps 0.8 lc rgb "#0072b2" title "σ_v from the percussions", \
     data using (1e3*$1):3 with points pt 5 ps 0.6 lc rgb "#009e73" title "σ_h = (σ_{xx} + σ_{yy})/2", \
     data using (1e3*$1):7 with points pt 9 ps 0.7 lc rgb "#cc79a7" title "σ_w on the walls", \
     data using (1e3*$1):5 with lines lw 2 lc rgb "#d55e00" title "Janssen, fitted λ", \
     data using (1e3*$1):6 with lines lw 1 dt 2 lc rgb "#000000" title "hydrostatic ρ_b g d"
