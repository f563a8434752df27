# cmake -DDOXYGEN=... -DDOXYFILE=... -DBOOK_DIR=... -DMATHJAX_DIR=... -DPYTHON=... -P run_doxygen.cmake
#
# Runs Doxygen on the book and fails, listing every warning, unless there are none. The parts of
# the local MathJax that the book uses are copied (not linked) into the HTML tree, so that the book
# typesets its mathematics offline, also after its folder has been copied elsewhere.
file(MAKE_DIRECTORY ${BOOK_DIR}/html)
execute_process(COMMAND ${PYTHON} ${CMAKE_CURRENT_LIST_DIR}/copy_mathjax.py ${MATHJAX_DIR} ${BOOK_DIR}/html
                RESULT_VARIABLE copied)
if(NOT copied EQUAL 0)
  message(FATAL_ERROR "Could not copy MathJax into the book (exit code ${copied})")
endif()
file(REMOVE ${BOOK_DIR}/doxygen-warnings.log)
execute_process(COMMAND ${DOXYGEN} ${DOXYFILE} RESULT_VARIABLE result)
file(READ ${BOOK_DIR}/doxygen-warnings.log warnings)
if(NOT result EQUAL 0 OR NOT warnings STREQUAL "")
  message(FATAL_ERROR "The book must build without Doxygen warnings (exit code ${result}):\n${warnings}")
endif()
message(STATUS "Book: ${BOOK_DIR}/html/index.html (no warnings)")
