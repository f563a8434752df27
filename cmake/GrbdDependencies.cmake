# Every dependency of grbd comes from a Debian 12 package and is found here, once, for all
# chapters. A missing one stops the configure step and names the package to install;
# scripts/setup installs them all.

set(GRBD_MISSING_PACKAGES "")
macro(grbd_require found what debian_package)
  if(NOT ${found})
    list(APPEND GRBD_MISSING_PACKAGES ${debian_package})
    message(SEND_ERROR "grbd needs ${what}: install the Debian package '${debian_package}' "
                       "(sudo apt-get install ${debian_package}), or run scripts/setup.")
  endif()
endmacro()

# Eigen 3.4 (linear algebra; header only).
find_package(Eigen3 3.4 QUIET NO_MODULE)
grbd_require(Eigen3_FOUND "Eigen >= 3.4" libeigen3-dev)

# SUNDIALS 6.4 (CVODE and ARKODE, chapter 3).
find_package(SUNDIALS 6.4 QUIET CONFIG)
grbd_require(SUNDIALS_FOUND "SUNDIALS >= 6.4" libsundials-dev)

# Boost.Math (header only): Jacobi elliptic functions and elliptic integrals for the closed-form
# references of chapter 3.
find_package(Boost 1.74 QUIET CONFIG)
if(Boost_FOUND)
  find_path(GRBD_BOOST_MATH_ELLIPTIC boost/math/special_functions/jacobi_elliptic.hpp
            HINTS ${Boost_INCLUDE_DIRS})
endif()
grbd_require(GRBD_BOOST_MATH_ELLIPTIC "Boost.Math (jacobi_elliptic.hpp)" libboost-math-dev)

# Open MPI (chapter 8).
find_package(MPI QUIET COMPONENTS C CXX)
grbd_require(MPI_FOUND "MPI (Open MPI) for C and C++" "libopenmpi-dev openmpi-bin")
find_program(GRBD_MPIEXEC NAMES mpiexec mpirun HINTS ${MPI_HOME} PATH_SUFFIXES bin)
grbd_require(GRBD_MPIEXEC "the mpiexec launcher" openmpi-bin)

# Parallel HDF5 built against Open MPI (chapters 7 and 8).
set(HDF5_PREFER_PARALLEL TRUE)
find_package(HDF5 QUIET COMPONENTS C)
if(HDF5_FOUND AND NOT HDF5_IS_PARALLEL)
  message(SEND_ERROR "grbd needs the parallel (MPI) build of HDF5, but found a serial one "
                     "(${HDF5_C_INCLUDE_DIRS}): install the Debian package 'libhdf5-openmpi-dev'.")
endif()
grbd_require(HDF5_FOUND "parallel HDF5" libhdf5-openmpi-dev)

# GoogleTest and Google Benchmark.
if(GRBD_BUILD_TESTS)
  find_package(GTest QUIET)
  grbd_require(GTest_FOUND "GoogleTest" libgtest-dev)
endif()
# CLI11 (header only): the command lines of the programs (ch05_fclib; the grbd tool of Chapter 7).
find_package(CLI11 2.1 QUIET CONFIG)
grbd_require(CLI11_FOUND "CLI11 >= 2.1 (command lines)" libcli11-dev)

# toml++ 3: the scene files of Chapter 7.
find_package(tomlplusplus 3 QUIET CONFIG)
grbd_require(tomlplusplus_FOUND "toml++ >= 3 (scene files)" libtomlplusplus-dev)

# The rest serves the book's project (GRBD_FULL_PROJECT: chapters, tests, book), not the library.
if(GRBD_FULL_PROJECT)
  find_package(benchmark QUIET)
  grbd_require(benchmark_FOUND "Google Benchmark" libbenchmark-dev)
endif()

# Python 3 runs the exercise generator, the grading script and the book's filter (standard
# library only).
if(GRBD_FULL_PROJECT OR GRBD_BUILD_TESTS OR GRBD_BUILD_BOOK)
  find_package(Python3 QUIET COMPONENTS Interpreter)
  grbd_require(Python3_FOUND "Python 3" python3)
endif()

# h5py and NumPy of Debian's own Python 3: chapter 7's tests and examples read output files as a
# user does. The interpreter is /usr/bin/python3, where Debian's packages are installed (another
# python3 earlier on PATH would not see them).
if(GRBD_BUILD_TESTS)
  find_program(GRBD_SYSTEM_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH)
  if(GRBD_SYSTEM_PYTHON)
    execute_process(COMMAND ${GRBD_SYSTEM_PYTHON} -c "import h5py, numpy"
                    RESULT_VARIABLE _grbd_h5py OUTPUT_QUIET ERROR_QUIET)
    if(_grbd_h5py EQUAL 0)
      set(GRBD_H5PY_FOUND TRUE)
    endif()
  endif()
  grbd_require(GRBD_H5PY_FOUND "h5py for /usr/bin/python3 (chapter 7's tests read output files)"
               python3-h5py)
endif()

# gnuplot draws the figures of the chapters from the data the demo programs write.
if(GRBD_FULL_PROJECT)
  find_program(GRBD_GNUPLOT gnuplot)
  grbd_require(GRBD_GNUPLOT "gnuplot (the figures of the book)" gnuplot-nox)
endif()

# Doxygen 1.9 and a local MathJax 2 for the book, which must render without a network.
if(GRBD_BUILD_BOOK)
  find_package(Doxygen 1.9 QUIET)
  grbd_require(DOXYGEN_FOUND "Doxygen >= 1.9" doxygen)
  find_path(GRBD_MATHJAX_DIR MathJax.js PATHS /usr/share/javascript/mathjax /usr/share/mathjax
            NO_DEFAULT_PATH)
  grbd_require(GRBD_MATHJAX_DIR "a local copy of MathJax 2" "libjs-mathjax fonts-mathjax")
endif()

if(GRBD_MISSING_PACKAGES)
  list(JOIN GRBD_MISSING_PACKAGES " " _grbd_missing)
  message(FATAL_ERROR "Missing dependencies. On Debian 12: sudo apt-get install ${_grbd_missing}")
endif()

# The FCLIB problems that chapter 5's tests, bench program and figure solve ship with the
# repository (chapters/05-contact-laws/data, see its README for their origin and licence).
set(GRBD_FCLIB_DATA_DIR ${PROJECT_SOURCE_DIR}/chapters/05-contact-laws/data)
