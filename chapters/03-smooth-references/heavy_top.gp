# Figure ch03_heavy_top (chapter 3): a heavy symmetric top (m = 0.5 kg, l = 4 cm,
# Θ⊥ = 2e-4 kg m², Θ3 = 3e-4 kg m²) released at a tilt of 30°, spinning at 150 rad/s about its
# axis, integrated by CVODE (BDF, rtol 1e-10, |p| = 1 projected). Left: u = cos ϑ of its
# symmetry axis against time, with the nutation band [u_min, u_max] from the roots of the cubic
# (α − βu)(1 − u²) − (b − au)². Right: the path of the tip of the unit axis seen from above, with
# the circles of radius √(1 − u²) of the band.
#
# Data: heavy_top.csv and nutation_bounds.csv from the demo ch03_closed_forms (closed_forms.cpp).
# Run as
#   gnuplot -e "datadir='<data directory>'; outfile='<figure>.svg'" heavy_top.gp
if (!exists("datadir") || !exists("outfile")) {
  print "heavy_top.gp: set datadir and outfile, as in"
  print "  gnuplot -e \"datadir='DIR'; outfile='FILE.svg'\" heavy_top.gp"
  exit status 2
}

motion = sprintf("%s/heavy_top.csv", datadir)
bounds = sprintf("%s/nutation_bounds.csv", datadir)
set datafile separator comma
stats bounds using 1 nooutput
u_min = STATS_min
stats bounds using 2 nooutput
u_max = STATS_min

set terminal svg size 900,430 dynamic enhanced font 'sans,12'
set output outfile

set multiplot layout 1,2 \
    title "Heavy top released at 30°: nutation band from the cubic (dashed) and CVODE" \
    font 'sans,13'

set xlabel "time t [s]"
set ylabel "u = cos ϑ of the symmetry axis"
set xrange [0:1.5]
set yrange [u_min - 0.2*(u_max - u_min) : u_max + 0.35*(u_max - u_min)]
set grid xtics ytics
set key top right horizontal font 'sans,12'
plot motion using 1:2 with lines lw 1.5 lc rgb "#0072b2" title "CVODE", \
     u_min with lines dt 2 lw 1.5 lc rgb "#d55e00" title "u_{min}, u_{max}", \
     u_max with lines dt 2 lw 1.5 lc rgb "#d55e00" notitle

set xlabel "axis tip, x"
set ylabel "axis tip, y"
set size ratio -1
r_out = sqrt(1 - u_min**2)
r_in = sqrt(1 - u_max**2)
set xrange [-1.1*r_out:1.1*r_out]
set yrange [-1.1*r_out:1.1*r_out]
set xtics 0.2
set ytics 0.2
unset key
set parametric
set trange [0:2*pi]
plot motion using 3:4 with lines lw 1.2 lc rgb "#0072b2", \
     r_out*cos(t), r_out*sin(t) with lines dt 2 lw 1.5 lc rgb "#d55e00", \
     r_in*cos(t), r_in*sin(t) with lines dt 2 lw 1.5 lc rgb "#d55e00"
unset parametric
unset multiplot
