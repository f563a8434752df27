# Figure ch05_fclib (chapter 5) when the FCLIB problems are not available: a notice in place of
# the convergence plot, so that the book still builds. CMake uses it when GRBD_FCLIB_DATA_DIR is
# empty. Run as
#   gnuplot -e "outfile='<figure>.svg'" fclib_missing.gp
if (!exists("outfile")) {
  print "fclib_missing.gp: set outfile, as in  gnuplot -e \"outfile='FILE.svg'\" fclib_missing.gp"
  exit status 2
}
set terminal svg size 1200,200 dynamic enhanced font 'sans,14'
set output outfile
unset border
unset tics
unset key
set xrange [0:1]
set yrange [0:1]
set label 1 "The FCLIB problems (shared/data/fclib) were not found when this book was built:" at 0.5,0.62 center
set label 2 "configure with -DGRBD_FCLIB_DATA_DIR=<folder> and rebuild to draw this figure." at 0.5,0.38 center
plot NaN notitle
