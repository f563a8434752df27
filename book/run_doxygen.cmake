# cmake -DDOXYGEN=... -DDOXYFILE=... -DBOOK_DIR=... -DMATHJAX_DIR=... -P run_doxygen.cmake
#
# Runs Doxygen on the book and fails, listing every warning, unless there are none. The local
# MathJax is linked into the HTML tree so that the book typesets its mathematics offline.
file(MAKE_DIRECTORY ${BOOK_DIR}/html)
if(NOT EXISTS ${BOOK_DIR}/html/mathjax)
  file(CREATE_LINK ${MATHJAX_DIR} ${BOOK_DIR}/html/mathjax SYMBOLIC)
endif()
file(REMOVE ${BOOK_DIR}/doxygen-warnings.log)
execute_process(COMMAND ${DOXYGEN} ${DOXYFILE} RESULT_VARIABLE result)
file(READ ${BOOK_DIR}/doxygen-warnings.log warnings)
if(NOT result EQUAL 0 OR NOT warnings STREQUAL "")
  message(FATAL_ERROR "The book must build without Doxygen warnings (exit code ${result}):\n${warnings}")
endif()
message(STATUS "Book: ${BOOK_DIR}/html/index.html (no warnings)")
