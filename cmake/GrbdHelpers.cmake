# Compiler flags shared by every grbd target.
add_library(grbd_flags INTERFACE)
target_compile_options(grbd_flags INTERFACE -Wall -Wextra -Wpedantic
                                            $<$<BOOL:${GRBD_WERROR}>:-Werror>)
if(GRBD_SANITIZE)
  target_compile_options(grbd_flags INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                              -fno-sanitize-recover=all)
  target_link_options(grbd_flags INTERFACE -fsanitize=address,undefined)
endif()

# The exercises of every chapter, read from the markers in solutions/: a list of "N.M" strings.
function(grbd_chapter_exercises chapter_dir out_var)
  file(GLOB _files CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/solutions/${chapter_dir}/*.cpp)
  set(_ids "")
  foreach(_file IN LISTS _files)
    file(STRINGS ${_file} _lines REGEX "BEGIN EXERCISE [0-9]+\\.[0-9]+")
    foreach(_line IN LISTS _lines)
      string(REGEX MATCH "BEGIN EXERCISE ([0-9]+\\.[0-9]+)" _m "${_line}")
      list(APPEND _ids ${CMAKE_MATCH_1})
    endforeach()
  endforeach()
  list(REMOVE_DUPLICATES _ids)
  list(SORT _ids COMPARE NATURAL)
  set(${out_var} ${_ids} PARENT_SCOPE)
endfunction()

# grbd_add_chapter_subdirectories(): add_subdirectory() for every chapter folder NN-topic of the
# current source folder that has a CMakeLists.txt, in the order of their numbers: the chapters are
# the folders, listed nowhere else (chapters/, tests/ and the book take them from there).
function(grbd_add_chapter_subdirectories)
  file(GLOB _dirs LIST_DIRECTORIES true RELATIVE ${CMAKE_CURRENT_SOURCE_DIR}
       ${CMAKE_CURRENT_SOURCE_DIR}/[0-9][0-9]-*)
  list(SORT _dirs)
  foreach(_dir IN LISTS _dirs)
    if(EXISTS ${CMAKE_CURRENT_SOURCE_DIR}/${_dir}/CMakeLists.txt)
      add_subdirectory(${_dir})
    endif()
  endforeach()
endfunction()
