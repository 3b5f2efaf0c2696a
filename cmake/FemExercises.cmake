# Which chapters a student builds from exercises/ (FEM_EXERCISES), checked. Included by
# FemChapter.cmake before any chapter is registered.
#
# FEM_EXERCISES as a student types it: "5" means chapter 05; anything else that is not a chapter
# number (or "all") is an error now, and a number no fem_add_chapter registers is one at the end of
# configuring (fem_check_exercise_chapters), instead of a build that silently uses the solutions.
if(NOT FEM_EXERCISES STREQUAL "all")
  set(fem_exercise_chapters "")
  foreach(entry IN LISTS FEM_EXERCISES)
    if(entry MATCHES "^[0-9]$")
      set(entry "0${entry}")
    elseif(NOT entry MATCHES "^[0-9][0-9]$")
      message(FATAL_ERROR "FEM_EXERCISES: '${entry}' is not a chapter number; use e.g. -DFEM_EXERCISES=05, \"01;05\" or all")
    endif()
    list(APPEND fem_exercise_chapters ${entry})
  endforeach()
  set(FEM_EXERCISES ${fem_exercise_chapters})
endif()

function(fem_check_exercise_chapters)
  if(FEM_EXERCISES STREQUAL "all")
    return()
  endif()
  foreach(number IN LISTS FEM_EXERCISES)
    if(NOT TARGET fem_ch${number})
      message(FATAL_ERROR "FEM_EXERCISES: there is no chapter ${number} in this build (chapters: ${FEM_ALL_CHAPTERS})")
    endif()
  endforeach()
endfunction()
cmake_language(DEFER DIRECTORY ${CMAKE_SOURCE_DIR} CALL fem_check_exercise_chapters)
